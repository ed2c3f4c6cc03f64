"""Training targets (paper, Ground Truth): binary ``(H, W)`` masks built from a shard's labels.

* ``vertex`` (VertexNet): the vertices of the A* path.
* ``path`` (the NRRT* baseline network): every cell of the A* path.

``endpoints`` says which of the path's two ends the target keeps (:data:`ENDPOINTS`):
``both`` (the paper's figure, whose segments end at start and goal), ``goal`` (the goal
only: the root of the tree needs no samples), ``none`` (the paper's turning formula, which
needs ``x_{i-3}`` and so never marks the first or last cells). Both kinds are dilated by the
same disk of ``radius`` pixels (:func:`vnrrt.grid.disk`; 0 = the cells alone, the paper's
reading). Masks are indexed ``mask[y, x]`` like grids.
"""

from __future__ import annotations

import cv2
import numpy as np

from vnrrt.grid import disk

TARGETS = ("vertex", "path")
# The target whose heatmap each heatmap planner samples (paper): VertexNet's vertices for
# VNRRT* and M-VNRRT*, the NRRT* network's path cells for NRRT*.
PLANNER_TARGETS = {"nrrt_star": "path", "vnrrt_star": "vertex", "m_vnrrt_star": "vertex"}
ENDPOINTS = ("both", "goal", "none")


def dilate(mask: np.ndarray, radius: float) -> np.ndarray:
    """``(H, W)`` bool: the cells within Euclidean distance ``radius`` of a True cell of
    ``mask`` ``(H, W)``. Radius 0 returns a copy of the mask."""
    mask = np.asarray(mask, dtype=bool)
    if radius < 1:
        return mask.copy()  # the disk of radius < 1 is the centre cell only
    kernel = disk(radius).astype(np.uint8)
    return cv2.dilate(mask.astype(np.uint8), kernel, borderType=cv2.BORDER_CONSTANT).astype(bool)


def cells_mask(cells: np.ndarray, shape: tuple[int, int], radius: float = 0.0) -> np.ndarray:
    """``(H, W)`` bool mask of integer cells ``(K, 2)`` (x, y), dilated by ``radius`` pixels."""
    mask = np.zeros(shape, dtype=bool)
    arr = np.asarray(cells, dtype=np.int64).reshape(-1, 2)
    mask[arr[:, 1], arr[:, 0]] = True
    return dilate(mask, radius)


def check_target(kind: str, radius: float, endpoints: str = "both") -> None:
    """Raise ``ValueError`` for an unknown target kind or endpoints option, or a negative
    radius."""
    if kind not in TARGETS:
        raise ValueError(f"unknown target {kind!r}; expected one of {TARGETS}")
    if endpoints not in ENDPOINTS:
        raise ValueError(f"unknown target endpoints {endpoints!r}; expected one of {ENDPOINTS}")
    if not radius >= 0:
        raise ValueError(f"target radius must be >= 0 pixels, got {radius!r}")


def _drop_ends(cells: np.ndarray, path: np.ndarray, endpoints: str) -> np.ndarray:
    """``cells`` (K, 2) without the path's start (``goal``) or start and goal (``none``)."""
    drop = {"both": [], "goal": [path[0]], "none": [path[0], path[-1]]}[endpoints]
    keep = np.ones(len(cells), bool)
    for end in drop:
        keep &= np.any(cells != end, axis=1)
    return cells[keep]


def target_mask(path: np.ndarray, vertices: np.ndarray, shape: tuple[int, int], kind: str,
                radius: float = 0, endpoints: str = "both") -> np.ndarray:  # fmt: skip
    """The ``(H, W)`` bool target of one instance from its A* ``path`` ``(T+1, 2)`` and its
    ``vertices`` ``(K, 2)`` (cells x, y): ``kind`` ``"vertex"`` or ``"path"``, keeping
    ``endpoints`` (module doc), dilated by ``radius`` pixels."""
    check_target(kind, radius, endpoints)
    path = np.asarray(path, np.int64).reshape(-1, 2)
    cells = np.asarray(vertices if kind == "vertex" else path, np.int64).reshape(-1, 2)
    return cells_mask(_drop_ends(cells, path, endpoints), shape, radius)


def label_masks(path: np.ndarray, vertices: np.ndarray, shape: tuple[int, int]) -> dict:
    """The undilated ``(H, W)`` bool masks the heatmap metrics compare against
    (:func:`vnrrt.predict.batch.heatmap_metrics`): ``path`` (all path cells), ``vertices``
    (start and goal included), ``interior`` (vertices without start and goal) and
    ``endpoints`` (start and goal)."""
    path = np.asarray(path, np.int64).reshape(-1, 2)
    vertices = np.asarray(vertices, np.int64).reshape(-1, 2)
    return {
        "path": cells_mask(path, shape),
        "vertices": cells_mask(vertices, shape),
        "interior": cells_mask(_drop_ends(vertices, path, "none"), shape),
        "endpoints": cells_mask(path[[0, -1]], shape),
    }
