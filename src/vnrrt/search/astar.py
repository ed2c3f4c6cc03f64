"""Optimal 8-connected grid paths: single-query A* and one-search-per-goal distance fields.

Graph (shared by both searches, coordinates as in :mod:`vnrrt.grid`):

* nodes are the free cells ``(x, y)`` of an ``(H, W)`` grid (nonzero = obstacle);
* a straight move (E, S, W, N) costs 1, a diagonal move costs sqrt(2) (octile costs);
* **no corner cutting**: a diagonal move from ``(x, y)`` to ``(x+dx, y+dy)`` is allowed
  only when both orthogonal neighbours ``(x+dx, y)`` and ``(x, y+dy)`` are free. The
  graph is therefore undirected, and reachability equals 4-connectivity of free cells.

Lengths are float64 sums of 1 and sqrt(2). Two optimal candidates are treated as equal
when their lengths differ by less than :data:`EPS`; distinct values ``a + b*sqrt(2)``
with ``|a|, |b| < 5000`` differ by far more than that.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from vnrrt.grid import MOVE_COSTS, MOVES, NoPathError, as_cell, as_occupancy
from vnrrt.search.anyangle import any_angle_path
from vnrrt.search.heap import heap_new, heap_pop, heap_push

EPS = 1e-7
_DX = MOVES[:, 0].copy()  # module-level constant arrays, frozen into the numba kernels
_DY = MOVES[:, 1].copy()
_COST = MOVE_COSTS.copy()


@njit(cache=True)
def move_masks(grid: np.ndarray) -> np.ndarray:
    """Allowed moves ``(H, W)`` uint8: bit ``m`` is set when move ``m`` of
    :data:`vnrrt.grid.MOVES` leaves free cell ``(x, y)`` to a free in-bounds cell without
    cutting a corner. Obstacle cells have no moves. Computed once, shared by searches."""
    h, w = grid.shape
    masks = np.zeros((h, w), np.uint8)
    for y in range(h):
        for x in range(w):
            if grid[y, x]:
                continue
            bits = 0
            for m in range(8):
                nx, ny = x + _DX[m], y + _DY[m]
                if nx < 0 or ny < 0 or nx >= w or ny >= h or grid[ny, nx]:
                    continue
                if m >= 4 and (grid[y, nx] or grid[ny, x]):
                    continue
                bits |= 1 << m
            masks[y, x] = bits
    return masks


@njit(cache=True, inline="always")
def _octile(v, w, gx, gy):
    ax, ay = abs(v % w - gx), abs(v // w - gy)
    return max(ax, ay) + (math.sqrt(2.0) - 1.0) * min(ax, ay)


@njit(cache=True)
def _search_kernel(masks, src, dst, targets):
    """Best-first search over flat cell indices ``v = y * W + x`` from ``src``.

    With ``dst >= 0``: A* towards ``dst`` (octile heuristic), stopping when ``dst`` is
    closed. With ``dst < 0``: Dijkstra, stopping once every index in ``targets`` (K,) is
    closed (all cells if K == 0). Returns ``g`` (H*W,) float64: lengths from ``src``,
    exact on closed cells, upper bounds on open ones, inf where unreached.
    """
    h, w = masks.shape
    flat = masks.ravel()
    g = np.full(h * w, np.inf)
    closed = np.zeros(h * w, np.uint8)
    pending = np.zeros(h * w, np.uint8)
    remaining = 0
    for t in targets:
        if pending[t] == 0:
            pending[t] = 1
            remaining += 1
    off = _DY * w + _DX
    gx, gy = (dst % w, dst // w) if dst >= 0 else (0, 0)
    keys, values, size = heap_new(8 * h * w + 1)
    g[src] = 0.0
    heap_push(keys, values, size, 0.0, src)
    while size[0] > 0:
        _, v = heap_pop(keys, values, size)
        if closed[v]:
            continue
        closed[v] = 1
        if v == dst:
            break
        if pending[v]:
            remaining -= 1
            if remaining == 0:
                break
        bits = flat[v]
        for m in range(8):
            if bits & (1 << m):
                n = v + off[m]
                ng = g[v] + _COST[m]
                if ng < g[n] - 1e-12:
                    g[n] = ng
                    key = ng + _octile(n, w, gx, gy) if dst >= 0 else ng
                    heap_push(keys, values, size, key, n)
    return g.reshape(h, w)


@njit(cache=True, inline="always")
def _guide_distance(x, y, guide):
    """Distance from point ``(x, y)`` to the polyline ``guide`` (K, 2), K >= 2."""
    best = np.inf
    for k in range(guide.shape[0] - 1):
        ax, ay = guide[k, 0], guide[k, 1]
        dx, dy = guide[k + 1, 0] - ax, guide[k + 1, 1] - ay
        ll = dx * dx + dy * dy
        t = 0.0 if ll == 0.0 else min(1.0, max(0.0, ((x - ax) * dx + (y - ay) * dy) / ll))
        best = min(best, math.hypot(x - ax - t * dx, y - ay - t * dy))
    return best


@njit(cache=True)
def descend_kernel(masks, dist, sx, sy, gx, gy, eps, guide, tol):
    """Follow a distance field from ``(sx, sy)`` down to the goal; return ``(moves, ok)``.

    At each cell the candidates are the moves ``m`` with ``dist[next] + cost[m] ==
    dist[cur]`` (within ``eps``): exactly the first moves of optimal paths, so every
    tie-break gives an optimal path. With an empty ``guide`` (tie-break ``turns``), ties keep
    the previous move when it is a candidate, else take the candidate best aligned with the
    straight line to the goal (largest cosine), then the lowest move code. With a polyline
    ``guide`` (K, 2) in pixels (tie-breaks ``line`` and ``exact``), ties take the candidate
    that keeps the previous move while its next cell centre lies within ``tol`` px of it,
    else the one whose next cell centre lies closest (then the previous move, then the
    lowest code): ``tol`` 0 hugs the guide in a staircase, a larger one trades closeness
    for fewer turns.
    ``moves`` is (T,) int8 chain codes; ``ok`` is False if the field is inconsistent.
    """
    h, w = masks.shape
    moves = np.empty(h * w, np.int8)
    n, x, y, prev = 0, sx, sy, -1
    guided = guide.shape[0] >= 2
    while x != gx or y != gy:
        best, best_score, bits = -1, np.inf, masks[y, x]
        tx, ty = gx - x, gy - y
        norm = math.sqrt(tx * tx + ty * ty)
        for m in range(8):
            if not bits & (1 << m):
                continue
            nx, ny = x + _DX[m], y + _DY[m]
            if abs(dist[ny, nx] + _COST[m] - dist[y, x]) > eps:
                continue
            if guided:
                d = _guide_distance(nx + 0.5, ny + 0.5, guide)
                if d <= tol:  # near enough: keep the direction, else the closest
                    score = 1e-3 * d - (1.0 if m == prev else 0.0)
                else:
                    score = (d - tol) * 1.001 - (1e-9 if m == prev else 0.0)
            elif m == prev:
                best = m
                break
            else:
                score = -(_DX[m] * tx + _DY[m] * ty) / (_COST[m] * norm)
            if score < best_score - 1e-12:
                best, best_score = m, score
        if best < 0 or n == h * w:
            return moves[:0], False
        moves[n] = best
        n += 1
        x, y, prev = x + _DX[best], y + _DY[best], best
    return moves[:n], True


TIE_BREAKS = ("turns", "line", "exact")
NO_GUIDE = np.zeros((0, 2))


def guide_for(tie_break: str, grid: np.ndarray, start, goal) -> np.ndarray:
    """The polyline ``(K, 2)`` a tie-break follows between the cells ``start`` and ``goal``:
    none (``turns``), the straight segment between their centres (``line``) or the exact
    continuous optimum's turning points (``exact``)."""
    if tie_break not in TIE_BREAKS:
        raise ValueError(f"unknown tie-break {tie_break!r}; known: {TIE_BREAKS}")
    if tie_break == "turns":
        return NO_GUIDE
    centres = np.array([start, goal], np.float64) + 0.5
    if tie_break == "line":
        return centres
    return any_angle_path(grid, centres[0], centres[1])[0]


def moves_to_path(start: tuple[int, int], moves: np.ndarray) -> np.ndarray:
    """Cells ``(T+1, 2)`` int64 (x, y) visited from ``start`` by chain codes ``moves`` (T,).

    Chain codes index :data:`vnrrt.grid.MOVES`.
    """
    steps = MOVES[np.asarray(moves, dtype=np.int64)]
    path = np.empty((len(steps) + 1, 2), dtype=np.int64)
    path[0] = start
    np.cumsum(steps, axis=0, out=path[1:])
    path[1:] += path[0]
    return path


def path_length(path: np.ndarray) -> float:
    """Octile length of an 8-connected cell path ``(T+1, 2)``: sum of 1 and sqrt(2) steps."""
    steps = np.abs(np.diff(np.asarray(path), axis=0))
    n_diag = int(np.count_nonzero(steps.min(axis=1)))
    return (len(steps) - n_diag) + n_diag * math.sqrt(2.0)


def astar(grid: np.ndarray, start, goal, tie_break: str = "turns",
          tolerance: float = 0.0) -> tuple[np.ndarray, float]:  # fmt: skip
    """Optimal 8-connected path from ``start`` to ``goal`` (graph rules in the module doc).

    Args:
        grid: ``(H, W)`` bool/int array, nonzero = obstacle, indexed ``grid[y, x]``.
        start, goal: integer cells ``(x, y)`` in free space.

    Returns:
        ``(path, length)``: ``path`` ``(T+1, 2)`` int64 cells (x, y) from start to goal
        inclusive; ``length`` its octile length (float, pixel units). Among equally short
        paths ``tie_break`` chooses (:func:`descend_kernel`): ``'turns'`` fewest turns,
        ``'line'`` closest to the straight start-goal line, ``'exact'`` closest to the exact
        continuous optimum, the last two within ``tolerance`` px.

    Raises:
        GridError: malformed grid, or start/goal outside the grid or on an obstacle.
        NoPathError: goal not reachable from start.
    """
    occ = as_occupancy(grid)
    sx, sy = as_cell(occ, start, "start")
    gx, gy = as_cell(occ, goal, "goal")
    # Search from the goal (the graph is undirected), then walk down its g field from the
    # start with the same tie-breaking as the dataset labeller (:func:`descend`).
    masks = move_masks(occ)
    empty = np.zeros(0, np.int64)
    g = _search_kernel(masks, gy * occ.shape[1] + gx, sy * occ.shape[1] + sx, empty)
    guide = guide_for(tie_break, occ, (sx, sy), (gx, gy))
    moves = descend(masks, g, (sx, sy), (gx, gy), guide, tolerance)
    return moves_to_path((sx, sy), moves), float(g[sy, sx])


def distance_field(masks: np.ndarray, goal, targets: np.ndarray | None = None) -> np.ndarray:
    """Optimal path lengths ``(H, W)`` float64 from every cell to ``goal`` (inf: unreachable).

    With ``targets`` (``(K, 2)`` int cells x, y) the search stops once all of them are
    settled: their values and those of every cell on their optimal paths are exact, the
    rest may be upper bounds. One search serves all starts of a goal (the graph is
    undirected). ``masks`` comes from :func:`move_masks` of the occupancy grid.
    """
    w = masks.shape[1]
    tg = np.zeros((0, 2), np.int64) if targets is None else np.asarray(targets, np.int64)
    return _search_kernel(masks, int(goal[1]) * w + int(goal[0]), -1, tg[:, 1] * w + tg[:, 0])


def descend(
    masks: np.ndarray, dist: np.ndarray, start, goal, guide=NO_GUIDE, tol: float = 0.0
) -> np.ndarray:
    """Chain codes ``(T,)`` int8 of an optimal path from ``start`` to the goal of ``dist``.

    ``masks`` is :func:`move_masks` of the grid; ``dist`` comes from
    :func:`distance_field` for ``goal`` with ``start`` among its targets. Tie-breaking
    (fewest turns first, or closest to ``guide`` within ``tol`` px: :func:`guide_for`) is
    described in :func:`descend_kernel`.
    """
    sx, sy, gx, gy = int(start[0]), int(start[1]), int(goal[0]), int(goal[1])
    if not np.isfinite(dist[sy, sx]):
        raise NoPathError(f"no path from start {(sx, sy)} to goal {(gx, gy)}: not connected")
    moves, ok = descend_kernel(
        masks, dist, sx, sy, gx, gy, EPS, np.asarray(guide, np.float64), float(tol)
    )
    if not ok:
        raise RuntimeError(f"distance field inconsistent at start {(sx, sy)}; was it a target?")
    return moves
