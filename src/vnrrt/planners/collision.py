"""Exact segment-versus-grid collision test (coordinates as in :mod:`vnrrt.grid`).

Semantics, chosen to be conservative and stated once here:

* Obstacle cells are **closed** unit squares ``[x, x+1] x [y, y+1]``. A segment collides
  when it touches any such square, boundary included, so a segment passing *exactly*
  through a corner touches all four cells meeting there (both diagonal neighbours
  count as touched), and a segment running exactly along a cell edge touches the cells
  on both sides of it.
* The area outside the ``(H, W)`` grid counts as obstacle: a segment touching the map
  border (``x == 0``, ``x == W``, ...) collides.
* A margin of :data:`MARGIN` pixels absorbs floating-point rounding: a cell is touched
  when the segment comes within ``MARGIN`` of it (in each axis).

The test walks the segment column by column (a supercover traversal): for each grid
column the segment crosses, it computes the exact ``y`` extent of the segment inside
that column and checks every cell of the column in that extent. No touched cell is ever
skipped, and the work is proportional to the number of touched cells. Coordinates outside
the map, infinite or NaN give False.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

MARGIN = 1e-9  # pixels


@njit(cache=True)
def segment_free(occ: np.ndarray, x0: float, y0: float, x1: float, y1: float) -> bool:
    """True when segment ``(x0, y0)-(x1, y1)`` (pixels) touches no obstacle cell.

    ``occ`` is an ``(H, W)`` occupancy grid (nonzero = obstacle; uint8 as the planners pass
    it, any numeric or bool dtype works), indexed ``occ[y, x]``. See the module docstring
    for the exact (closed, conservative) rule.
    """
    h, w = occ.shape
    if x0 > x1:  # walk left to right
        x0, y0, x1, y1 = x1, y1, x0, y0
    if not (x0 - MARGIN >= 0.0 and x1 + MARGIN < w):  # the border touched (or NaN: False)
        return False
    c_lo = int(math.floor(x0 - MARGIN))
    c_hi = int(math.floor(x1 + MARGIN))
    dx = x1 - x0
    if not dx > 0.0:  # vertical (or a point): each column holds the segment's whole y extent
        if not (y0 - MARGIN >= 0.0 and y1 - MARGIN >= 0.0 and y0 + MARGIN < h and y1 + MARGIN < h):
            return False
        r_lo = int(math.floor(min(y0, y1) - MARGIN))
        r_hi = int(math.floor(max(y0, y1) + MARGIN))
        for cx in range(c_lo, c_hi + 1):
            for cy in range(r_lo, r_hi + 1):
                if occ[cy, cx]:
                    return False
        return True
    slope = (y1 - y0) / dx
    ya = y0  # y at the first column's left end (x0)
    y_end = y0 + (x1 - x0) * slope  # and at the last one's right end (x1)
    ok = ya - MARGIN >= 0.0 and y_end - MARGIN >= 0.0 and ya + MARGIN < h and y_end + MARGIN < h
    if not ok:  # y is monotone in x (so are its rounded values): the ends bound every column
        return False
    for cx in range(c_lo, c_hi + 1):
        # Part of the segment inside the closed column [cx, cx + 1], clamped to [x0, x1]: from
        # the previous column's right end (ya) to this one's (yb).
        xb = max(min(x1, float(cx + 1)), x0)
        yb = y0 + (xb - x0) * slope
        # Rows and column as unsigned ints: >= 0 (checked above), so truncation is floor, and
        # the two-cell step's indexing needs no wraparound test.
        r_lo = np.uintp(min(ya, yb) - MARGIN)
        r_hi = np.uintp(max(ya, yb) + MARGIN)
        ya = yb
        c = np.uintp(cx)
        if r_hi - r_lo <= 1:  # one or two cells (a shallow segment): tested without a loop
            if (occ[r_lo, c] != 0) | (occ[r_hi, c] != 0):  # any dtype (uint8, bool, float)
                return False
        else:
            for cy in range(r_lo, r_hi + 1):
                if occ[cy, c]:
                    return False
    return True


@njit(cache=True)
def path_free(occ: np.ndarray, path: np.ndarray) -> bool:
    """True when every segment of polyline ``path`` ``(K, 2)`` float (x, y) is free.

    A single point (``K == 1``) is tested as a zero-length segment.
    """
    if path.shape[0] == 1:
        return segment_free(occ, path[0, 0], path[0, 1], path[0, 0], path[0, 1])
    for i in range(path.shape[0] - 1):
        if not segment_free(occ, path[i, 0], path[i, 1], path[i + 1, 0], path[i + 1, 1]):
            return False
    return True


def point_free(occ: np.ndarray, point) -> bool:
    """True when the point ``(x, y)`` touches no obstacle cell and no map border."""
    x, y = float(point[0]), float(point[1])
    return bool(segment_free(occ, x, y, x, y))


def polyline_length(path: np.ndarray) -> float:
    """Euclidean length (pixels) of a polyline ``(K, 2)`` (x, y); 0 for ``K < 2``."""
    p = np.asarray(path, dtype=np.float64)
    if len(p) < 2:
        return 0.0
    d = p[1:] - p[:-1]  # np.diff's values, without its overhead
    return float(np.add.reduce(np.hypot(d[:, 0], d[:, 1])))  # np.sum's pairwise sum
