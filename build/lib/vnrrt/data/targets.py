"""Training targets (paper, Ground Truth): binary ``(H, W)`` masks built from a shard's labels.

* ``vertex`` (VertexNet): the vertices of the A* path, start and goal included.
* ``path`` (the NRRT* baseline network): every cell of the A* path.

Each can be dilated by a disk of ``radius`` pixels (:func:`vnrrt.grid.disk`; 0 = the cells
alone, the paper's reading). Masks are indexed ``mask[y, x]`` like grids.
"""

from __future__ import annotations

import cv2
import numpy as np

from vnrrt.grid import disk

TARGETS = ("vertex", "path")


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


def check_target(kind: str, radius: float) -> None:
    """Raise ``ValueError`` for an unknown target kind or a negative radius."""
    if kind not in TARGETS:
        raise ValueError(f"unknown target {kind!r}; expected one of {TARGETS}")
    if not radius >= 0:
        raise ValueError(f"target radius must be >= 0 pixels, got {radius!r}")


def target_mask(
    path: np.ndarray, vertices: np.ndarray, shape: tuple[int, int], kind: str, radius: float = 0
) -> np.ndarray:
    """The ``(H, W)`` bool target of one instance from its A* ``path`` ``(T+1, 2)`` and its
    ``vertices`` ``(K, 2)`` (cells x, y): ``kind`` ``"vertex"`` or ``"path"``, dilated by
    ``radius`` pixels."""
    check_target(kind, radius)
    return cells_mask(vertices if kind == "vertex" else path, shape, radius)
