"""Oracle heatmaps: what a perfect network could tell each sampler, built from the labels
(a heatmap source beside the trained networks: :mod:`vnrrt.evaluation.sources`).

Targets (``start``/``goal`` are integer cells as in :func:`vnrrt.search.astar`):

* ``oracle_path``: the cells of the A* path (what the NRRT* network learns);
* ``oracle_vertex``: the interior vertices of the A* path (the paper's turning points,
  start and goal excluded);
* ``oracle_vertex_endpoints``: the vertices with start and goal (what the VertexNet target
  teaches);
* ``oracle_endpoints``: start and goal only (a control);
* ``oracle_taut_path``: the segments of the exact continuous shortest path
  (:func:`vnrrt.search.any_angle_path`), rasterised at 4 points per pixel;
* ``oracle_taut_vertex``: its interior turning points (convex obstacle corners, points at
  pixel corners; each spreads its weight over the four pixels that meet there);
* ``oracle_blend``: :func:`blend` of the A* path and interior-vertex oracles at weight ``w``
  (:data:`BLEND_PARTS`).

Each target is blurred with a Gaussian of ``sigma`` pixels (0: none), set to zero outside
the allowed cells (the obstacle rule: every cell, or the free cells), scaled to a maximum of
1 (so that tau keeps its meaning for M-VNRRT*), then lifted by a uniform ``floor``:
``H = floor + (1 - floor) H`` on the allowed cells. A target with no cell (a straight path has
no interior vertex) gives the uniform map. :func:`dilute` degrades a heatmap towards uniform
(signal fraction ``q``).

An oracle source is written ``kind[@w<w>][@s<sigma>][@q<q>]`` (:class:`OracleSource`):
``oracle_vertex@s4``, ``oracle_blend@w0.25@s2``, ``oracle_path@s1@q0.1``; without ``@s``
the study's ``oracle.sigma``.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass

import cv2
import numpy as np

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
BLEND = "oracle_blend"
BLEND_PARTS = ("oracle_path", "oracle_vertex")  # H_w: (1 - w) the first, w the second
TARGET = {
    "oracle_path": "path",
    "oracle_vertex": "interior_vertices",
    "oracle_vertex_endpoints": "vertices",
    "oracle_endpoints": "endpoints",
    "oracle_taut_path": "taut_path",
    "oracle_taut_vertex": "taut_vertices",
    BLEND: "path",  # measured near the path (the vertices lie on it)
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


def finish(img: np.ndarray, allowed: np.ndarray, sigma: float, floor: float) -> np.ndarray:
    """Blur by ``sigma`` px, zero the cells outside ``allowed`` ``(H, W)`` bool (the
    obstacle rule, :func:`vnrrt.evaluation.sources.allowed_cells`), scale to max 1, lift
    by ``floor``: ``(H, W)`` float32 in [0, 1] (module doc)."""
    if not (sigma >= 0 and math.isfinite(sigma)):
        raise ValueError(f"sigma must be finite and >= 0 pixels, got {sigma!r}")
    if not 0.0 <= floor <= 1.0:
        raise ValueError(f"floor must be in [0, 1], got {floor!r}")
    out = img.astype(np.float64)
    if sigma > 0:
        k = 2 * int(math.ceil(4 * sigma)) + 1
        out = cv2.GaussianBlur(out, (k, k), sigma, borderType=cv2.BORDER_CONSTANT)
    out = np.where(allowed, out, 0.0)
    top = out.max()
    out = out / top if top > 0 else allowed.astype(np.float64)
    out = np.where(allowed, floor + (1.0 - floor) * out, 0.0)
    return out.astype(np.float32)


def oracle_heatmap(kind: str, grid: np.ndarray, start, goal, sigma: float = 1.0,
                   floor: float = 0.0, zero_obstacles: bool = False) -> np.ndarray:  # fmt: skip
    """The oracle heatmap ``kind`` (module doc) of one instance: ``(H, W)`` float32 in
    [0, 1] with maximum 1, indexed ``[y, x]`` like ``grid``; ``start``/``goal`` are integer
    cells ``(x, y)``. Computes the A* path and the exact optimum itself."""
    occ = as_occupancy(grid)
    s, g = as_cell(occ, start, "start"), as_cell(occ, goal, "goal")
    path, _ = astar(occ, s, g)
    centres = cell_center(np.array([s, g]))
    exact, _ = any_angle_path(occ, centres[0], centres[1])
    allowed = occ == 0 if zero_obstacles else np.ones(occ.shape, bool)
    return finish(target_image(kind, occ.shape, path, exact), allowed, sigma, floor)


def dilute(heatmap: np.ndarray, allowed: np.ndarray, q: float) -> np.ndarray:
    """Signal fraction ``q`` of the heatmap's sampling mass kept, ``1 - q`` spread uniformly
    over the ``allowed`` cells; scaled to a maximum of 1 (``q = 0``: uniform, ``q = 1``:
    unchanged up to scale). ``(H, W)`` float32."""
    if not 0.0 <= q <= 1.0:
        raise ValueError(f"signal fraction q must be in [0, 1], got {q!r}")
    uniform = allowed / allowed.sum()
    h = np.where(allowed, np.asarray(heatmap, np.float64), 0.0)
    total = h.sum()
    signal = h / total if total > 0 else uniform
    out = q * signal + (1.0 - q) * uniform
    return (out / out.max()).astype(np.float32)


def blend(path: np.ndarray, vertex: np.ndarray, w: float) -> np.ndarray:
    """``H_w``: ``(1 - w)`` of the sampling mass from the path oracle ``path`` and ``w`` from
    the vertex oracle ``vertex`` (each part normalised to unit mass first: equal mass per
    part), scaled to a maximum of 1; ``w = 0`` is the path oracle, ``w = 1`` the vertex
    oracle (up to scale). ``(H, W)`` float32."""
    if not 0.0 <= w <= 1.0:
        raise ValueError(f"blend weight w must be in [0, 1], got {w!r}")
    parts = []
    for h in (np.asarray(path, np.float64), np.asarray(vertex, np.float64)):
        total = h.sum()
        parts.append(h / total if total > 0 else h)
    out = (1.0 - w) * parts[0] + w * parts[1]
    top = out.max()
    return (out / top if top > 0 else out).astype(np.float32)


@dataclass(frozen=True)
class OracleSource:
    """An oracle heatmap source (module doc): its ``kind`` (a target or :data:`BLEND`), the
    blend weight ``w`` (blends only), the blur ``sigma`` (px; None: the study's) and the
    signal fraction ``q`` (the quality curve; 1: the oracle itself)."""

    kind: str
    sigma: float | None = None
    q: float = 1.0
    w: float | None = None

    def __post_init__(self) -> None:
        if self.kind not in (*ORACLE_KINDS, BLEND):
            raise ValueError(f"unknown oracle {self.kind!r}; known: {(*ORACLE_KINDS, BLEND)}")
        if (self.kind == BLEND) != (self.w is not None):
            raise ValueError(f"{self.kind}: the blend, and only the blend, takes a weight w")

    @property
    def text(self) -> str:
        """The source's one written form (module doc)."""
        out = self.kind + ("" if self.w is None else f"@w{self.w:g}")
        out += "" if self.sigma is None else f"@s{self.sigma:g}"
        return out + ("" if self.q == 1.0 else f"@q{self.q:g}")

    @classmethod
    def parse(cls, text: str) -> OracleSource:
        """The source ``text`` writes; ``ValueError`` naming it otherwise."""
        kind, *fields = text.split("@")
        values: dict[str, float] = {}
        for f in fields:
            if f[:1] not in ("w", "s", "q") or f[0] in values:
                raise ValueError(f"bad oracle source {text!r}: expected kind[@w][@s][@q]")
            try:
                values[f[0]] = float(f[1:])
            except ValueError:
                raise ValueError(f"bad oracle source {text!r}: {f!r} is not a number") from None
        return cls(kind, values.get("s"), values.get("q", 1.0), values.get("w"))


def parse_source(source: str) -> tuple[str, float]:
    """``oracle_vertex@s2@q0.1`` -> ``("oracle_vertex", 0.1)``: the kind and ``q``."""
    o = OracleSource.parse(source)
    return o.kind, o.q


def source_name(kind: str, q: float = 1.0, sigma: float | None = None,
                w: float | None = None) -> str:  # fmt: skip
    """The heatmap source name of an oracle (:class:`OracleSource`)."""
    return OracleSource(kind, sigma, q, w).text


def instance_heatmap(source: str, inst, sigma: float | None, floor: float,
                     allowed: np.ndarray) -> np.ndarray:  # fmt: skip
    """The oracle ``source`` (:class:`OracleSource`; ``sigma``: the blur when the source
    names none) of an evaluation instance, from its stored labels
    (:class:`vnrrt.data.instances.EvalInstance`), zero outside ``allowed``."""
    o = OracleSource.parse(source)
    s = sigma if o.sigma is None else o.sigma
    if s is None:
        raise ValueError(f"oracle source {source!r} names no blur (@s<sigma>)")

    def one(kind: str) -> np.ndarray:
        img = target_image(kind, inst.grid.shape, inst.path, inst.exact_path, inst.vertices)
        return finish(img, allowed, s, floor)

    both = o.kind == BLEND
    heat = blend(one(BLEND_PARTS[0]), one(BLEND_PARTS[1]), o.w) if both else one(o.kind)
    return heat if o.q == 1.0 else dilute(heat, allowed, o.q)


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
