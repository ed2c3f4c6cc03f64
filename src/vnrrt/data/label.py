"""Ground truth of one base map: optimal paths and vertices for every start x goal pair.

One exact Dijkstra search from each goal (stopped once all starts are settled) serves all
starts of that goal; each path is then read off the distance field with the tie-breaking
of :func:`vnrrt.search.descend` (``labels.tie_break``), so it is identical to
``vnrrt.search.astar(grid, start, goal, tie_break)``'s path in all but rare ties.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numba import njit

from vnrrt.grid import MOVES
from vnrrt.maps.generate import FloorMap
from vnrrt.search.astar import (
    EPS,
    NoPathError,
    descend_kernel,
    distance_field,
    guide_for,
    move_masks,
)
from vnrrt.search.vertices import vertex_flags


@dataclass(frozen=True)
class MapLabels:
    """Labels of the ``N = n_goals * n_starts`` instances of one map, goal-major order.

    Attributes:
        start_index, goal_index: ``(N,)`` int64 indices into the map's starts / goals.
        length: ``(N,)`` float64 optimal octile length (pixels).
        moves: ``(P,)`` uint8 chain codes of all paths, concatenated.
        n_moves: ``(N,)`` int64 moves per path (a path has ``n_moves + 1`` cells).
        vertex_steps: ``(V,)`` uint32 path indices of all vertices, concatenated.
        n_vertices: ``(N,)`` int64 vertices per path.
    """

    start_index: np.ndarray
    goal_index: np.ndarray
    length: np.ndarray
    moves: np.ndarray
    n_moves: np.ndarray
    vertex_steps: np.ndarray
    n_vertices: np.ndarray


@njit(cache=True)
def _label_goal(masks, dist, starts, gx, gy, steps, eps, guides, goff, tol):
    """Paths from every start ``(K, 2)`` down ``dist`` to the goal, and their vertices;
    start ``i`` breaks ties along ``guides[goff[i]:goff[i+1]]`` (empty: fewest turns) within
    ``tol`` px.

    Returns ``(moves, n_moves, vsteps, n_vertices, ok)``: concatenated chain codes (uint8),
    moves per path (K,), concatenated vertex path indices (uint32), vertices per path (K,).
    """
    k = starts.shape[0]
    parts, vparts = [], []
    n_moves = np.zeros(k, np.int64)
    n_vert = np.zeros(k, np.int64)
    for i in range(k):
        sx, sy = starts[i, 0], starts[i, 1]
        guide = guides[goff[i] : goff[i + 1]]
        moves, ok = descend_kernel(masks, dist, sx, sy, gx, gy, eps, guide, tol)
        if not ok:
            return np.zeros(0, np.uint8), n_moves, np.zeros(0, np.uint32), n_vert, False
        path = np.empty((len(moves) + 1, 2), np.int64)
        path[0, 0], path[0, 1] = sx, sy
        for t in range(len(moves)):
            path[t + 1, 0] = path[t, 0] + MOVES[moves[t], 0]
            path[t + 1, 1] = path[t, 1] + MOVES[moves[t], 1]
        vidx = np.flatnonzero(vertex_flags(path, steps)).astype(np.uint32)
        parts.append(moves.astype(np.uint8))
        vparts.append(vidx)
        n_moves[i], n_vert[i] = len(moves), len(vidx)
    moves_all = _concat(parts, np.empty(n_moves.sum(), np.uint8))
    return moves_all, n_moves, _concat(vparts, np.empty(n_vert.sum(), np.uint32)), n_vert, True


@njit(cache=True)
def _concat(parts, out):
    """Concatenate the 1-D arrays ``parts`` into the preallocated ``out``; return it."""
    o = 0
    for p in parts:
        out[o : o + len(p)] = p
        o += len(p)
    return out


def _guides(grid, starts, goal, tie_break: str) -> tuple[np.ndarray, np.ndarray]:
    """The tie-break polylines of every start towards ``goal``, flat with offsets."""
    parts = [guide_for(tie_break, grid, tuple(s), tuple(goal)) for s in starts]
    goff = np.zeros(len(parts) + 1, np.int64)
    np.cumsum([len(p) for p in parts], out=goff[1:])
    flat = np.concatenate(parts) if goff[-1] else np.zeros((0, 2))
    return np.ascontiguousarray(flat, np.float64), goff


def label_map(fm: FloorMap, steps: list[int] | tuple[int, ...] = (1, 2, 3),
              tie_break: str = "turns", tolerance: float = 0.0) -> MapLabels:  # fmt: skip
    """Optimal paths and vertices of all start x goal pairs of ``fm`` (goal-major order);
    ``tie_break`` and ``tolerance`` (px) choose among equally short paths
    (:func:`vnrrt.search.astar.descend_kernel`)."""
    masks = move_masks(np.ascontiguousarray(fm.grid, np.uint8))
    starts = np.ascontiguousarray(fm.starts, np.int64)
    steps_arr = np.asarray(steps, np.int64)
    n_s, n_g = len(starts), len(fm.goals)
    cols: dict[str, list] = {k: [] for k in ("len", "mv", "nm", "vs", "nv")}
    for goal in fm.goals:
        dist = distance_field(masks, goal, starts)
        if not np.all(np.isfinite(dist[starts[:, 1], starts[:, 0]])):
            raise NoPathError(f"goal {tuple(goal)} does not reach every start of its map")
        guides, goff = _guides(fm.grid, starts, goal, tie_break)
        moves, n_moves, vsteps, n_vert, ok = _label_goal(
            masks, dist, starts, int(goal[0]), int(goal[1]), steps_arr, EPS, guides, goff, tolerance
        )
        if not ok:
            raise RuntimeError(f"inconsistent distance field for goal {tuple(goal)}")
        lengths = dist[starts[:, 1], starts[:, 0]]
        for key, val in zip(cols, (lengths, moves, n_moves, vsteps, n_vert)):
            cols[key].append(val)
    return MapLabels(
        start_index=np.tile(np.arange(n_s), n_g),
        goal_index=np.repeat(np.arange(n_g), n_s),
        length=np.concatenate(cols["len"]),
        moves=np.concatenate(cols["mv"]),
        n_moves=np.concatenate(cols["nm"]),
        vertex_steps=np.concatenate(cols["vs"]),
        n_vertices=np.concatenate(cols["nv"]),
    )
