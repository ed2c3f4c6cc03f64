"""The exact continuous (any-angle) shortest path on an occupancy grid.

Model (coordinates as in :mod:`vnrrt.grid`):

* The grid is ``(H, W)``, indexed ``grid[y, x]``, nonzero = obstacle. Obstacle cells are
  **closed** unit squares ``[x, x+1] x [y, y+1]``; the area outside the map counts as
  blocked.
* Start and goal are continuous points ``(x, y)`` (pixels) in free cells (dataset
  instances use cell centres ``(x + 0.5, y + 0.5)``).
* The answer is the infimum of the lengths of paths that touch no obstacle cell: exactly
  what a continuous planner using the conservative test of
  :func:`vnrrt.planners.collision.segment_free` can approach but never beat. In the
  limit a path may touch an obstacle corner, run along an obstacle edge or along the map
  border, but it may not pass through a **pinch** vertex (two diagonally opposite cells
  blocked, the other two free: the free cells meet only in a point of both obstacles),
  nor run along an edge with blocked cells (or the outside) on both sides.

Consequences used here:

* A shortest path is a polyline that bends only at **convex corners**: grid vertices
  where exactly one of the four cells meeting there is blocked (outside counts as
  blocked, so no vertex on the map border is convex).
* Visibility (:func:`segment_visible`): split the segment P->Q at its crossings with the
  integer grid lines. Every piece's interior must lie in the interior of a free cell,
  or, for an axis-parallel piece lying on a grid line, on a unit edge with at least one
  free cell beside it; and no grid vertex strictly inside the segment may be a pinch
  vertex. Endpoints may lie on cell boundaries.
* Bitangent rule: a corner whose single blocked cell lies in quadrant ``(sx, sy)``
  (``+1``: the cell is on the +x / +y side of the vertex) can be on a shortest path only
  along lines tangent to that cell, i.e. directions ``(dx, dy)`` for which neither
  ``(dx, dy)`` nor ``(-dx, -dy)`` points into the cell's interior; ``(dx, dy)`` points
  into it iff ``dx*sx > 0 and dy*sy > 0``.
* Taut rule: a path p -> c -> v bending at corner c is locally shortest only when the
  blocked cell lies inside the turn, i.e. the cell's diagonal ``(sx, sy)`` lies strictly
  inside the cone spanned by ``p - c`` and ``v - c`` (or the path goes straight on).
  Otherwise a short cut near ``c`` is free and strictly shorter, so no shortest path to
  ``v`` uses that bend; pruning such successors during A* is exact.

Algorithm: A* over the visibility graph whose nodes are the convex corners plus start
and goal, Euclidean heuristic, visibility computed lazily per expanded node (each pair
is tested at most once, and only when the edge would improve a tentative distance and
could still beat the best goal distance found). Start and goal are checked for
4-connectivity of free cells first (connectivity in this model equals that), so a
disconnected query fails fast with :class:`vnrrt.search.NoPathError`. On the project's
random 200x200 maps (200-800 convex corners) a query takes ~0.5 ms (max ~5 ms).

Exactness: the visibility test uses float arithmetic with a tolerance :data:`TOL`
(1e-9 px) for "lies on a grid line / vertex". With coordinates that are multiples of
0.5 (cell centres and corners) and maps up to a few hundred cells, every breakpoint of
a segment is a ratio of small integers, so distinct breakpoints are at least ~1e-4 px
apart while float rounding stays below ~1e-12: the test is exact. The bitangent and taut
tests only multiply differences of such coordinates, which floats represent exactly.
For arbitrary float endpoints the test is exact up to :data:`TOL`.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from vnrrt.grid import NoPathError, as_occupancy, as_point
from vnrrt.search.heap import heap_new, heap_pop, heap_push

TOL = 1e-9  # pixels: "on a grid line" tolerance of the visibility test


@njit(cache=True, inline="always")
def _blocked(occ, x, y):
    h, w = occ.shape
    return x < 0 or y < 0 or x >= w or y >= h or occ[y, x] != 0


@njit(cache=True, inline="always")
def _pinch(occ, k, j):
    """True when vertex ``(k, j)`` has exactly two diagonally opposite blocked cells."""
    a = _blocked(occ, k - 1, j - 1)
    b = _blocked(occ, k, j - 1)
    c = _blocked(occ, k - 1, j)
    d = _blocked(occ, k, j)
    return (a and d and not b and not c) or (b and c and not a and not d)


@njit(cache=True)
def segment_visible(occ: np.ndarray, x0: float, y0: float, x1: float, y1: float) -> bool:
    """True when segment ``(x0, y0)-(x1, y1)`` (pixels) is a limit of obstacle-free paths.

    ``occ`` is an ``(H, W)`` uint8 occupancy grid (nonzero = obstacle) indexed
    ``occ[y, x]``. The rule (pieces between grid-line crossings in free cells or on
    edges with a free side, no pinch vertex strictly inside) is in the module docstring.
    A zero-length segment is visible.
    """
    dx = x1 - x0
    dy = y1 - y0
    if abs(dx) <= TOL and abs(dy) <= TOL:
        return True
    if abs(dx) <= TOL:  # vertical
        lo, hi = min(y0, y1), max(y0, y1)
        r0, r1 = int(math.floor(lo + TOL)), int(math.ceil(hi - TOL))
        k = int(round(x0))
        if abs(x0 - k) <= TOL:  # on the grid line x = k: unit edges [j, j+1]
            for j in range(r0, r1):
                if _blocked(occ, k - 1, j) and _blocked(occ, k, j):
                    return False
            for j in range(r0 + 1, r1):
                if _pinch(occ, k, j):
                    return False
        else:
            c = int(math.floor(x0))
            for r in range(r0, r1):
                if _blocked(occ, c, r):
                    return False
        return True
    if abs(dy) <= TOL:  # horizontal
        lo, hi = min(x0, x1), max(x0, x1)
        c0, c1 = int(math.floor(lo + TOL)), int(math.ceil(hi - TOL))
        j = int(round(y0))
        if abs(y0 - j) <= TOL:  # on the grid line y = j: unit edges [k, k+1]
            for k in range(c0, c1):
                if _blocked(occ, k, j - 1) and _blocked(occ, k, j):
                    return False
            for k in range(c0 + 1, c1):
                if _pinch(occ, k, j):
                    return False
        else:
            r = int(math.floor(y0))
            for c in range(c0, c1):
                if _blocked(occ, c, r):
                    return False
        return True
    if x0 > x1:  # walk left to right, column by column
        x0, y0, x1, y1 = x1, y1, x0, y0
    slope = (y1 - y0) / (x1 - x0)
    c0, c1 = int(math.floor(x0 + TOL)), int(math.ceil(x1 - TOL))
    ya = y0
    for c in range(c0, c1):
        xb = min(x1, float(c + 1))
        yb = y0 + (xb - x0) * slope if xb < x1 else y1
        lo, hi = min(ya, yb), max(ya, yb)
        for r in range(int(math.floor(lo + TOL)), int(math.ceil(hi - TOL))):
            if _blocked(occ, c, r):
                return False
        if c + 1 < c1:  # the column line x = c + 1 is strictly inside the segment
            j = int(round(yb))
            if abs(yb - j) <= TOL and _pinch(occ, c + 1, j):
                return False
        ya = yb
    return True


@njit(cache=True)
def _corners_kernel(occ):
    """Convex corners ``(N, 2)`` int64 (x, y) in row-major vertex order, and the quadrant
    ``(N, 2)`` int64 ``(sx, sy)`` of each one's blocked cell."""
    h, w = occ.shape
    pts = np.empty(((h + 1) * (w + 1), 2), np.int64)
    quad = np.empty(((h + 1) * (w + 1), 2), np.int64)
    n = 0
    for j in range(1, h):  # border vertices are never convex
        for k in range(1, w):
            a = 1 if occ[j - 1, k - 1] else 0
            b = 1 if occ[j - 1, k] else 0
            c = 1 if occ[j, k - 1] else 0
            d = 1 if occ[j, k] else 0
            if a + b + c + d != 1:
                continue
            pts[n, 0], pts[n, 1] = k, j
            quad[n, 0] = 1 if b + d else -1
            quad[n, 1] = 1 if c + d else -1
            n += 1
    return pts[:n].copy(), quad[:n].copy()


@njit(cache=True)
def _cells_at(occ, x, y):
    """Free cells ``(K, 2)`` int64 (x, y) whose closed square contains point ``(x, y)``
    (one cell for an interior point, up to four for a point on a vertex)."""
    out = np.empty((4, 2), np.int64)
    n = 0
    for cy in range(int(math.floor(y - TOL)), int(math.floor(y + TOL)) + 1):
        for cx in range(int(math.floor(x - TOL)), int(math.floor(x + TOL)) + 1):
            if not _blocked(occ, cx, cy):
                out[n, 0], out[n, 1] = cx, cy
                n += 1
    return out[:n]


@njit(cache=True)
def _connected(occ, sx, sy, gx, gy):
    """True when a free cell at point ``(sx, sy)`` is 4-connected to one at ``(gx, gy)``
    (for points in free space, connectivity of the model equals 4-connectivity of cells)."""
    h, w = occ.shape
    seen = np.zeros((h, w), np.uint8)
    stack = np.empty(h * w, np.int64)
    n = 0
    for c in _cells_at(occ, sx, sy):
        if not seen[c[1], c[0]]:
            seen[c[1], c[0]] = 1
            stack[n] = c[1] * w + c[0]
            n += 1
    while n > 0:
        n -= 1
        v = stack[n]
        x, y = v % w, v // w
        for m in range(4):
            nx = x + (1 if m == 0 else (-1 if m == 1 else 0))
            ny = y + (1 if m == 2 else (-1 if m == 3 else 0))
            if 0 <= nx < w and 0 <= ny < h and occ[ny, nx] == 0 and seen[ny, nx] == 0:
                seen[ny, nx] = 1
                stack[n] = ny * w + nx
                n += 1
    found = False
    for c in _cells_at(occ, gx, gy):
        found = found or seen[c[1], c[0]] != 0
    return found


@njit(cache=True, inline="always")
def _into(dx, dy, sx, sy):
    """True when the line with direction (dx, dy) through a corner with blocked quadrant
    (sx, sy) enters the blocked cell's interior on one side (not a tangent)."""
    a = dx * sx
    b = dy * sy
    return (a > 0.0 and b > 0.0) or (a < 0.0 and b < 0.0)


@njit(cache=True)
def _search_kernel(occ, corners, quad, sx, sy, gx, gy):
    """A* over convex corners + start (index N) + goal (N + 1). Returns ``parent`` (N+2,)
    int64 and ``g`` (N+2,) float64; ``g[N + 1]`` is inf when the goal was not reached."""
    n = corners.shape[0]
    m = n + 2
    s, t = n, n + 1
    px = np.empty(m)
    py = np.empty(m)
    qx = np.zeros(m)
    qy = np.zeros(m)
    for i in range(n):
        px[i], py[i] = corners[i, 0], corners[i, 1]
        qx[i], qy[i] = quad[i, 0], quad[i, 1]
    px[s], py[s], px[t], py[t] = sx, sy, gx, gy
    hv = np.empty(m)
    for i in range(m):
        hv[i] = math.sqrt((px[i] - gx) ** 2 + (py[i] - gy) ** 2)
    g = np.full(m, np.inf)
    parent = np.full(m, -1, np.int64)
    closed = np.zeros(m, np.uint8)
    keys, values, size = heap_new(4 * m + 16)
    g[s] = 0.0
    heap_push(keys, values, size, hv[s], s)
    while size[0] > 0:
        _, u = heap_pop(keys, values, size)
        if closed[u]:
            continue
        closed[u] = 1
        if u == t:
            break
        ux, uy, gu = px[u], py[u], g[u]
        corner = u < n
        p = parent[u]
        taut = corner and p >= 0
        ax = ay = aq = 0.0
        if taut:  # a = p - u, q = blocked diagonal; successors must keep q inside the turn
            ax, ay = px[p] - ux, py[p] - uy
            aq = ax * qy[u] - ay * qx[u]
        for v in range(m):
            if closed[v]:
                continue
            dx, dy = px[v] - ux, py[v] - uy
            cand = gu + math.sqrt(dx * dx + dy * dy)
            if cand >= g[v] or cand + hv[v] >= g[t]:
                continue
            if corner and _into(dx, dy, qx[u], qy[u]):
                continue
            if v < n and _into(dx, dy, qx[v], qy[v]):
                continue
            if taut:
                ab = ax * dy - ay * dx
                if ab == 0.0:
                    if ax * dx + ay * dy >= 0.0:  # not straight on
                        continue
                elif aq * ab <= 0.0 or (qx[u] * dy - qy[u] * dx) * ab <= 0.0:
                    continue
            if not segment_visible(occ, ux, uy, px[v], py[v]):
                continue
            g[v] = cand
            parent[v] = u
            if size[0] == keys.shape[0]:  # grow the heap
                nk, nv, _ = heap_new(2 * keys.shape[0])
                nk[: size[0]] = keys
                nv[: size[0]] = values
                keys, values = nk, nv
            heap_push(keys, values, size, cand + hv[v], v)
    return parent, g


def convex_corners(grid: np.ndarray) -> np.ndarray:
    """Convex obstacle corners ``(N, 2)`` int64 grid vertices ``(x, y)``, row-major order.

    A vertex is convex when exactly one of the four cells meeting there is blocked
    (outside the map counts as blocked, so border vertices never are).
    """
    return _corners_kernel(as_occupancy(grid))[0]


def _drop_straight(path: np.ndarray) -> np.ndarray:
    """Remove interior points where the polyline goes straight on."""
    keep = [0]
    for i in range(1, len(path) - 1):
        a, b, c = path[keep[-1]], path[i], path[i + 1]
        u, v = b - a, c - b
        if abs(u[0] * v[1] - u[1] * v[0]) <= TOL and u @ v > 0:
            continue
        keep.append(i)
    keep.append(len(path) - 1)
    return path[keep]


def any_angle_path(grid: np.ndarray, start, goal) -> tuple[np.ndarray, float]:
    """Exact shortest obstacle-free path from ``start`` to ``goal`` (model in module doc).

    Args:
        grid: ``(H, W)`` bool/int array, nonzero = obstacle, indexed ``grid[y, x]``.
        start, goal: continuous points ``(x, y)`` in pixels, in free cells.

    Returns:
        ``(points, length)``: the turning points ``(K, 2)`` float64 ``(x, y)`` from start
        to goal inclusive (interior points are convex corners; ``K == 2`` when the goal
        is directly visible), and the path length in pixels.

    Raises:
        GridError: malformed grid, or start/goal outside the grid or in an obstacle cell.
        NoPathError: start and goal are not connected.
    """
    occ = as_occupancy(grid)
    sx, sy = as_point(occ, start, "start")
    gx, gy = as_point(occ, goal, "goal")
    straight = np.array([[sx, sy], [gx, gy]], dtype=np.float64)
    if segment_visible(occ, sx, sy, gx, gy):
        return straight, math.hypot(gx - sx, gy - sy)
    if not _connected(occ, sx, sy, gx, gy):
        raise NoPathError(f"no path from start {(sx, sy)} to goal {(gx, gy)}: not connected")
    corners, quad = _corners_kernel(occ)
    parent, g = _search_kernel(occ, corners, quad, sx, sy, gx, gy)
    n = len(corners)
    if not np.isfinite(g[n + 1]):
        raise NoPathError(f"no path from start {(sx, sy)} to goal {(gx, gy)}")
    nodes = [n + 1]
    while nodes[-1] != n:
        nodes.append(int(parent[nodes[-1]]))
    pts = np.concatenate([corners.astype(np.float64), straight])[nodes[::-1]]
    pts = _drop_straight(pts)
    return pts, float(np.sum(np.hypot(*np.diff(pts, axis=0).T)))


def any_angle_length(grid: np.ndarray, start, goal) -> float:
    """Exact any-angle shortest path length (pixels); see :func:`any_angle_path`."""
    return any_angle_path(grid, start, goal)[1]
