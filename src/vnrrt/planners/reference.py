"""Reference lengths for the ``optimal`` stop rule (pixels).

* ``astar`` (the paper's): the optimal 8-connected, no-corner-cutting grid path between
  the cells containing start and goal (:func:`vnrrt.search.astar`), measured between
  cell centres. Continuous paths are ~5% shorter, so 1% above it is a loose target.
* ``any_angle``: the exact continuous shortest path length between the start and goal
  points (:func:`vnrrt.search.any_angle_length`): the infimum over paths that touch no
  obstacle cell, i.e. what a planner using the conservative test of :mod:`.collision`
  can approach but never beat. The tightest target.
* ``taut``: a cheaper approximation of ``any_angle``: the A* path pulled taut. From each
  kept vertex the walk jumps to the furthest later path cell whose centre is visible
  (segment free under the exact, conservative test of :mod:`.collision`), and the
  polyline through the kept centres, from the start cell's centre to the goal cell's
  centre, is measured (:func:`taut_length`). It is feasible, so for start and goal at
  cell centres never below ``any_angle``, but greedy shortcuts through cell centres
  miss the best path: on the project's random 200x200 maps it is a median ~0.3% and up
  to ~6% longer.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from vnrrt.grid import cell_center, point_to_cell
from vnrrt.planners.collision import polyline_length, segment_free
from vnrrt.planners.config import REFERENCES
from vnrrt.search import any_angle_length, astar


def _cells(start, goal) -> tuple[tuple[int, int], tuple[int, int]]:
    s, g = point_to_cell(np.array([start, goal], dtype=np.float64))
    return (int(s[0]), int(s[1])), (int(g[0]), int(g[1]))


def astar_length(occ: np.ndarray, start, goal) -> float:
    """Optimal octile length between the cells containing continuous points start/goal.

    Raises :class:`vnrrt.search.NoPathError` when they are not connected.
    """
    s, g = _cells(start, goal)
    return float(astar(occ, s, g)[1])


@njit(cache=True)
def _taut_indices(occ: np.ndarray, centres: np.ndarray) -> np.ndarray:
    n = centres.shape[0]
    keep = np.empty(n, np.int64)
    keep[0], k, i = 0, 1, 0
    while i < n - 1:
        j = n - 1
        while j > i + 1 and not segment_free(
            occ, centres[i, 0], centres[i, 1], centres[j, 0], centres[j, 1]
        ):
            j -= 1
        keep[k] = j
        k += 1
        i = j
    return keep[:k]


def taut_path(occ: np.ndarray, cells: np.ndarray) -> np.ndarray:
    """Any-angle polyline ``(K, 2)`` float64 (x, y) through centres of grid path ``cells``.

    ``cells`` is an ``(T+1, 2)`` int path (x, y) with free consecutive moves (an A* path).
    """
    centres = cell_center(cells)
    return centres[_taut_indices(occ, centres)]


def taut_length(occ: np.ndarray, start, goal) -> float:
    """Length of the taut A* path between the centres of the start and goal cells.

    An approximation of :func:`any_angle_length` from above (see module doc). Raises
    :class:`vnrrt.search.NoPathError` when start and goal are not connected.
    """
    s, g = _cells(start, goal)
    path, _ = astar(occ, s, g)
    return polyline_length(taut_path(occ, path))


def reference_length(occ: np.ndarray, start, goal, kind: str = "astar") -> float:
    """Reference length of kind ``'astar'``, ``'any_angle'`` (exact) or ``'taut'``
    (see module doc)."""
    if kind == "astar":
        return astar_length(occ, start, goal)
    if kind == "any_angle":
        return any_angle_length(occ, start, goal)
    if kind == "taut":
        return taut_length(occ, start, goal)
    raise ValueError(f"unknown reference {kind!r}; use one of {REFERENCES}")
