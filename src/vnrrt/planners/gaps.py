"""Narrow-passage cells of a grid: what the gap sampler draws from (``PlannerConfig.gap_share``).

The bridge test (Hsu et al., 2003) samples the midpoint of a short segment whose two ends
lie in obstacles and keeps it when it is free: a point in a narrow passage. On an occupancy
grid an axis-aligned form of it can be run over every cell at once instead of by rejection
(a passage at 45 degrees reads up to sqrt(2) wider than it is): a free cell is a **gap
cell** of width ``width`` when the run of free cells through it along its row or along its
column is at most ``width`` cells long; a run ends at an obstacle cell or at the
map border (outside the map counts as obstacle, as in :mod:`.collision`). A one-cell slit
through a wall, a 3-6 px gap, a corridor between an obstacle and the border are gap cells;
open space, and the free cells beside a single wall, are not.

Coordinates as in :mod:`vnrrt.grid`: ``occ`` is ``(H, W)`` uint8 indexed ``occ[y, x]``
(nonzero = obstacle); cells are returned as flat indices ``y * W + x``.
"""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True)
def gap_cells(occ: np.ndarray, width: int) -> np.ndarray:
    """Flat indices ``y * W + x`` (increasing, int64) of the gap cells of width ``width``
    (cells, >= 1) of the ``(H, W)`` grid ``occ`` (module doc): one pass over the rows, O(H W).
    A run is marked when the obstacle (or border) that ends it is met; ``top[x]`` is the first
    row of the run open in column ``x``, ``left`` the first column of the one open in the row."""
    h, w = occ.shape
    mark = np.zeros((h, w), np.bool_)
    top = np.zeros(w, np.int64)
    for y in range(h):
        left = 0
        for x in range(w):
            if occ[y, x]:
                t = top[x]
                if 0 < y - t <= width:
                    mark[t:y, x] = True
                top[x] = y + 1
                if 0 < x - left <= width:
                    mark[y, left:x] = True
                left = x + 1
        if 0 < w - left <= width:
            mark[y, left:w] = True
    for x in range(w):
        t = top[x]
        if 0 < h - t <= width:
            mark[t:h, x] = True
    return np.flatnonzero(mark).astype(np.int64)
