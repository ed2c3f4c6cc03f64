"""Heatmap sources: what a learned planner samples. A source is a trained network (its
predicted heatmap, read from the prediction files into :attr:`EvalInstance.heatmaps`) or an
oracle: what a perfect network could tell each sampler, built from the labels.

Oracle kinds (``start``/``goal`` are integer cells as in :func:`vnrrt.search.astar`):

* ``oracle_path``: the cells of the A* path (what the NRRT* network learns);
* ``oracle_vertex``: the interior vertices of the A* path (the paper's turning points,
  start and goal excluded);
* ``oracle_vertex_endpoints``: the vertices with start and goal (what the VertexNet target
  teaches);
* ``oracle_endpoints``: start and goal only (a control: what the quick VertexNet predicts);
* ``oracle_taut_path``: the segments of the exact continuous shortest path
  (:func:`vnrrt.search.any_angle_path`), rasterised at 4 points per pixel;
* ``oracle_taut_vertex``: its interior turning points (convex obstacle corners, points at
  pixel corners; each spreads its weight over the four pixels that meet there).

Each target is blurred with a Gaussian of ``sigma`` pixels (0: none), obstacle cells are set
to zero (a perfect network puts no mass where no sample can go), the map is scaled to a
maximum of 1 (so that tau keeps its meaning for M-VNRRT*), then lifted by a uniform
``floor``: ``H = floor + (1 - floor) H`` on free cells. A target with no cell (a straight
path has no interior vertex) gives the uniform map over free cells.

:func:`mix` degrades a heatmap towards uniform: signal fraction ``q`` of the sampling mass
from the heatmap, ``1 - q`` uniform over free cells.
"""

from __future__ import annotations

import itertools
import math

import cv2
import numpy as np

from vnrrt.data.heatmaps import HeatmapError
from vnrrt.grid import as_cell, as_occupancy, cell_center
from vnrrt.search import any_angle_path, astar, path_vertices

ORACLE_KINDS = (
    "oracle_path",
    "oracle_vertex",
    "oracle_vertex_endpoints",
    "oracle_endpoints",
    "oracle_taut_path",
    "oracle_taut_vertex",
)
TARGET = {
    "oracle_path": "path",
    "oracle_vertex": "interior_vertices",
    "oracle_vertex_endpoints": "vertices",
    "oracle_endpoints": "endpoints",
    "oracle_taut_path": "taut_path",
    "oracle_taut_vertex": "taut_vertices",
}


def _splat(img: np.ndarray, points: np.ndarray) -> None:
    """Add unit weight at continuous points ``(K, 2)`` (x, y), shared bilinearly among the
    pixels whose centres surround each point."""
    h, w = img.shape
    for x, y in np.asarray(points, np.float64).reshape(-1, 2):
        fx, fy = x - 0.5, y - 0.5  # pixel (i, j) has its centre at (i + 0.5, j + 0.5)
        x0, y0 = math.floor(fx), math.floor(fy)
        ax, ay = fx - x0, fy - y0
        for dx, dy, wgt in (
            (0, 0, (1 - ax) * (1 - ay)),
            (1, 0, ax * (1 - ay)),
            (0, 1, (1 - ax) * ay),
            (1, 1, ax * ay),
        ):
            px, py = min(max(x0 + dx, 0), w - 1), min(max(y0 + dy, 0), h - 1)
            img[py, px] += wgt


def _polyline_points(points: np.ndarray, per_px: int = 4) -> np.ndarray:
    """Points along a polyline ``(K, 2)``, ``per_px`` per pixel of length."""
    out = [points[:1]]
    for a, b in itertools.pairwise(points):
        n = max(1, int(math.ceil(per_px * float(np.hypot(*(b - a))))))
        t = (np.arange(1, n + 1) / n)[:, None]
        out.append(a + t * (b - a))
    return np.concatenate(out)


def target_image(
    kind: str,
    shape: tuple[int, int],
    path: np.ndarray,
    exact_path: np.ndarray,
    vertices: np.ndarray | None = None,
) -> np.ndarray:
    """The unblurred target of ``kind`` as an ``(H, W)`` float64 weight image, from an A*
    ``path`` (T+1, 2) cells, its ``vertices`` (K, 2) cells (start and goal included; computed
    from the path when None) and the exact optimum's turning points ``exact_path`` (Q, 2)."""
    if kind not in ORACLE_KINDS:
        raise ValueError(f"unknown oracle {kind!r}; known: {ORACLE_KINDS}")
    img = np.zeros(shape)
    if kind in ("oracle_taut_path", "oracle_taut_vertex"):
        pts = np.asarray(exact_path, np.float64)
        _splat(img, _polyline_points(pts) if kind == "oracle_taut_path" else pts[1:-1])
        return img
    path = np.asarray(path, np.int64)
    if kind == "oracle_path":
        cells = path
    elif kind == "oracle_endpoints":
        cells = path[[0, -1]]
    else:
        verts = path_vertices(path) if vertices is None else np.asarray(vertices, np.int64)
        cells = verts if kind == "oracle_vertex_endpoints" else verts[1:-1]
    img[cells[:, 1], cells[:, 0]] = 1.0
    return img


def finish(img: np.ndarray, occ: np.ndarray, sigma: float, floor: float) -> np.ndarray:
    """Blur by ``sigma`` px, zero obstacle cells, scale to max 1, lift by ``floor``:
    ``(H, W)`` float32 in [0, 1] (module doc)."""
    if not (sigma >= 0 and math.isfinite(sigma)):
        raise ValueError(f"sigma must be finite and >= 0 pixels, got {sigma!r}")
    if not 0.0 <= floor <= 1.0:
        raise ValueError(f"floor must be in [0, 1], got {floor!r}")
    out = img.astype(np.float64)
    if sigma > 0:
        k = 2 * int(math.ceil(4 * sigma)) + 1
        out = cv2.GaussianBlur(out, (k, k), sigma, borderType=cv2.BORDER_CONSTANT)
    free = occ == 0
    out = np.where(free, out, 0.0)
    top = out.max()
    out = out / top if top > 0 else free.astype(np.float64)
    out = np.where(free, floor + (1.0 - floor) * out, 0.0)
    return out.astype(np.float32)


def oracle_heatmap(
    kind: str, grid: np.ndarray, start, goal, sigma: float = 1.0, floor: float = 0.0
) -> np.ndarray:
    """The oracle heatmap ``kind`` (module doc) of one instance: ``(H, W)`` float32 in
    [0, 1] with maximum 1, indexed ``[y, x]`` like ``grid``; ``start``/``goal`` are integer
    cells ``(x, y)``. Computes the A* path and the exact optimum itself."""
    occ = as_occupancy(grid)
    s, g = as_cell(occ, start, "start"), as_cell(occ, goal, "goal")
    path, _ = astar(occ, s, g)
    centres = cell_center(np.array([s, g]))
    exact, _ = any_angle_path(occ, centres[0], centres[1])
    return finish(target_image(kind, occ.shape, path, exact), occ, sigma, floor)


def mix(heatmap: np.ndarray, grid: np.ndarray, q: float) -> np.ndarray:
    """Signal fraction ``q`` of the heatmap's sampling mass kept, ``1 - q`` spread uniformly
    over free cells; scaled to a maximum of 1 (``q = 0``: uniform, ``q = 1``: unchanged up to
    scale). ``(H, W)`` float32."""
    if not 0.0 <= q <= 1.0:
        raise ValueError(f"signal fraction q must be in [0, 1], got {q!r}")
    free = as_occupancy(grid) == 0
    h = np.where(free, np.asarray(heatmap, np.float64), 0.0)
    total = h.sum()
    signal = h / total if total > 0 else free / free.sum()
    out = q * signal + (1.0 - q) * free / free.sum()
    return (out / out.max()).astype(np.float32)


ORACLE_PREFIX = "oracle_"


def is_oracle(source: str | None) -> bool:
    """Whether a heatmap source is an oracle (else a network, or None: uniform)."""
    return source is not None and source.startswith(ORACLE_PREFIX)


def parse_source(source: str) -> tuple[str, float]:
    """``oracle_vertex`` -> ``("oracle_vertex", 1.0)``; ``oracle_vertex@q0.1`` -> q = 0.1."""
    kind, _, q = source.partition("@q")
    if kind not in ORACLE_KINDS:
        raise ValueError(f"unknown oracle source {source!r}; kinds: {ORACLE_KINDS}")
    return kind, float(q) if q else 1.0


def source_name(kind: str, q: float = 1.0) -> str:
    """The heatmap source name of an oracle at signal fraction ``q``."""
    return kind if q == 1.0 else f"{kind}@q{q:g}"


def instance_heatmap(source: str, inst, sigma: float = 1.0, floor: float = 0.0) -> np.ndarray:
    """The oracle ``source`` (``oracle_<kind>[@q<q>]``) of an evaluation instance, from its
    stored labels (:class:`vnrrt.evaluation.instances.EvalInstance`)."""
    kind, q = parse_source(source)
    img = target_image(kind, inst.grid.shape, inst.path, inst.exact_path, inst.vertices)
    heat = finish(img, inst.grid, sigma, floor)
    return heat if q == 1.0 else mix(heat, inst.grid, q)


def target_mask(inst, target: str) -> np.ndarray:
    """``(H, W)`` bool cells of an instance's ``target``: ``'path'`` (the A* path),
    ``'vertices'`` (its vertices), ``'interior_vertices'`` (without start and goal),
    ``'endpoints'`` (start and goal), ``'taut_path'`` (the cells the exact optimum crosses)
    or ``'taut_vertices'`` (the four pixels around each of its interior turning points)."""
    if target in ("taut_path", "taut_vertices"):
        img = np.zeros(inst.grid.shape)
        pts = np.asarray(inst.exact_path, np.float64)
        _splat(img, _polyline_points(pts) if target == "taut_path" else pts[1:-1])
        return img > 0
    cells = {
        "path": inst.path,
        "vertices": inst.vertices,
        "interior_vertices": inst.vertices[1:-1],
        "endpoints": inst.path[[0, -1]],
    }[target]
    mask = np.zeros(inst.grid.shape, bool)
    cells = np.asarray(cells, np.int64).reshape(-1, 2)
    mask[cells[:, 1], cells[:, 0]] = True
    return mask


def mass_near(heatmap: np.ndarray, mask: np.ndarray, radius: float) -> float:
    """Share of ``heatmap``'s mass within ``radius`` px of a True cell of ``mask`` (the
    metric the networks report, :class:`vnrrt.model.metrics.MassNear`); NaN when the mask
    is empty or the heatmap has no mass."""
    from vnrrt.data.targets import dilate

    h = np.asarray(heatmap, np.float64)
    total = h.sum()
    if not mask.any() or total <= 0:
        return math.nan
    return float(h[dilate(mask, radius)].sum() / total)


def source_heatmap(source: str, inst, sigma: float | None, floor: float | None) -> np.ndarray:
    """The heatmap a job samples: a network's (on the instance) or an oracle's (built with
    blur ``sigma`` px and uniform ``floor``, which an oracle needs), ``(H, W)``."""
    if source in inst.heatmaps:
        return inst.heatmaps[source]
    if is_oracle(source):
        if sigma is None or floor is None:
            raise ValueError(f"oracle source {source!r} needs oracle.sigma and oracle.floor")
        return instance_heatmap(source, inst, sigma, floor)
    known = sorted(inst.heatmaps)
    raise HeatmapError(f"instance {inst.map} has no {source!r} heatmap (known: {known})")


def source_target(source: str, network_targets: dict[str, str]) -> str:
    """The target a source's heatmap aims at (for ``heat_mass``): an oracle's, or the
    network's (``network_targets``; ``'path'`` or ``'interior_vertices'``)."""
    if is_oracle(source):
        return TARGET[parse_source(source)[0]]
    return network_targets.get(source, "path")


def mask_variant(heatmap: np.ndarray, variant: str, inst, endpoint_radius: float) -> np.ndarray:
    """``heatmap`` ``(H, W)`` prepared for M-VNRRT*'s mask variant
    (:data:`vnrrt.evaluation.keys.MASK_VARIANTS`): ``max`` divides it by its maximum (so tau
    reads as for the max-normalised oracles), ``noends`` zeroes the disks of
    ``endpoint_radius`` px around the start and goal cells; ``""`` leaves it."""
    h = np.asarray(heatmap, np.float64)
    if variant == "max":
        top = h.max()
        return h / top if top > 0 else h
    if variant == "noends":
        return np.where(endpoint_disks(inst, endpoint_radius), 0.0, h)
    if variant:
        raise ValueError(f"unknown mask variant {variant!r}")
    return h


def endpoint_disks(inst, radius: float) -> np.ndarray:
    """``(H, W)`` bool: the cells within ``radius`` px of the instance's start or goal cell."""
    from vnrrt.data.targets import dilate

    return dilate(target_mask(inst, "endpoints"), radius)


def mass_shares(weights: np.ndarray, inst, radius: float, endpoint_radius: float) -> dict:
    """Where a sampler's heatmap weights ``(H, W)`` lie, as shares of their total (NaN when
    they have none): ``mass_endpoints`` on the start/goal disks (``endpoint_radius``),
    ``mass_interior`` within ``radius`` px of the A* label's interior vertices (off those
    disks), ``mass_path`` within ``radius`` of the rest of the path (off both)."""
    from vnrrt.data.targets import dilate

    w = np.asarray(weights, np.float64)
    total = w.sum()
    if not total > 0:
        return {"mass_endpoints": math.nan, "mass_interior": math.nan, "mass_path": math.nan}
    ends = endpoint_disks(inst, endpoint_radius)
    interior = dilate(target_mask(inst, "interior_vertices"), radius) & ~ends
    path = dilate(target_mask(inst, "path"), radius) & ~ends & ~interior
    return {
        "mass_endpoints": float(w[ends].sum() / total),
        "mass_interior": float(w[interior].sum() / total),
        "mass_path": float(w[path].sum() / total),
    }
