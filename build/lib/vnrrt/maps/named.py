"""The five named maps (the paper's Maps 1-5 role, Fig. 4): fixed, of increasing difficulty.

Each is built deterministically from OpenCV primitives (no random state), 200x200 by
default, with one start and one goal cell (x, y):

1. ``open``: a few scattered blocks; a near-straight diagonal path.
2. ``cluttered``: 36 random obstacles of all kinds (fixed seed); many short detours.
3. ``narrow_passage``: a wall across the map, crossed only through one 4-pixel gap far
   from the straight line; start and goal on either side, near the wall's foot.
4. ``u_trap``: the start sits inside a large U whose opening faces away from the goal,
   so growing towards the goal runs into the U's base.
5. ``maze``: four staggered walls with narrow gaps at alternating ends: a long zigzag
   detour through narrow passages.

The harder ones defeat uniform sampling: the gaps cover a tiny share of the free space
and the greedy direction leads into dead ends.
"""

from __future__ import annotations

import cv2
import numpy as np

from vnrrt.maps.config import DataConfig
from vnrrt.maps.generate import FloorMap, draw_obstacles, largest_free_region

NAMES = ("open", "cluttered", "narrow_passage", "u_trap", "maze")


def _canvas(size: int) -> np.ndarray:
    return np.zeros((size, size), np.uint8)


def _rect(grid: np.ndarray, x0: float, y0: float, x1: float, y1: float) -> None:
    """Fill the cells of ``[x0, x1] x [y0, y1]`` given as fractions of the map size."""
    s = grid.shape[0]
    cv2.rectangle(grid, (round(x0 * s), round(y0 * s)), (round(x1 * s), round(y1 * s)), 1, -1)


def _cells(size: int, *pts: tuple[float, float]) -> np.ndarray:
    return np.array([[round(x * size), round(y * size)] for x, y in pts], np.int64)


def _open(size: int) -> FloorMap:
    g = _canvas(size)
    for x, y in [(0.25, 0.3), (0.6, 0.2), (0.45, 0.55), (0.75, 0.65), (0.2, 0.75)]:
        _rect(g, x, y, x + 0.08, y + 0.08)
    return FloorMap(g, _cells(size, (0.08, 0.92)), _cells(size, (0.92, 0.08)))


def _cluttered(size: int) -> FloorMap:
    """36 obstacles of all five kinds from a fixed-seed generator (PCG64 is stable)."""
    rng = np.random.default_rng(20240605)
    cfg = DataConfig(size=size, n_obstacles=[36, 36], obstacle_size=[0.08 * size, 0.16 * size])
    g = draw_obstacles(rng, cfg)
    region = largest_free_region(g)
    ys, xs = np.nonzero(region)
    start = np.argmin((xs - 0.03 * size) ** 2 + (ys - 0.97 * size) ** 2)
    goal = np.argmin((xs - 0.97 * size) ** 2 + (ys - 0.03 * size) ** 2)
    return FloorMap(g, np.array([[xs[start], ys[start]]]), np.array([[xs[goal], ys[goal]]]))


def _narrow_passage(size: int) -> FloorMap:
    g = _canvas(size)
    _rect(g, 0.48, 0.0, 0.52, 1.0)
    y0, gap = round(0.12 * size), max(2, round(0.02 * size))
    g[y0 : y0 + gap, :] = 0  # the only way through: gap x wall thickness cells
    return FloorMap(g, _cells(size, (0.3, 0.9)), _cells(size, (0.7, 0.9)))


def _u_trap(size: int) -> FloorMap:
    g = _canvas(size)
    _rect(g, 0.2, 0.6, 0.8, 0.65)  # base of the U, between start and goal
    _rect(g, 0.2, 0.15, 0.25, 0.65)  # left arm
    _rect(g, 0.75, 0.15, 0.8, 0.65)  # right arm
    _rect(g, 0.0, 0.8, 0.35, 0.84)  # ledges below that lengthen the way around
    _rect(g, 0.65, 0.8, 1.0, 0.84)
    return FloorMap(g, _cells(size, (0.5, 0.5)), _cells(size, (0.5, 0.95)))


def _maze(size: int) -> FloorMap:
    g = _canvas(size)
    gap = max(2, round(0.025 * size))
    for k, y in enumerate((0.2, 0.4, 0.6, 0.8)):
        _rect(g, 0.0, y, 1.0, y + 0.03)
        x0 = round((0.94 if k % 2 == 0 else 0.03) * size)  # gaps at alternating ends
        g[round(y * size) : round((y + 0.03) * size) + 1, x0 : x0 + gap] = 0
    return FloorMap(g, _cells(size, (0.1, 0.08)), _cells(size, (0.9, 0.92)))


_BUILDERS = {
    "open": _open,
    "cluttered": _cluttered,
    "narrow_passage": _narrow_passage,
    "u_trap": _u_trap,
    "maze": _maze,
}


def named_map(name: str, size: int = 200) -> FloorMap:
    """The named map ``name`` (one of :data:`NAMES`) at ``size`` x ``size`` pixels."""
    if name not in _BUILDERS:
        raise ValueError(f"unknown named map {name!r}; known: {', '.join(NAMES)}")
    fm = _BUILDERS[name](size)
    for kind, cells in (("start", fm.starts), ("goal", fm.goals)):
        x, y = cells[0]
        if fm.grid[y, x]:
            raise AssertionError(f"named map {name}: {kind} {(x, y)} on an obstacle")
    return fm
