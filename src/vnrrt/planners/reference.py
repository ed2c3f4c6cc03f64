"""Reference lengths for the ``optimal`` stop rule (pixels).

* ``astar`` (the paper's): the optimal 8-connected, no-corner-cutting grid path between
  the cells containing start and goal (:func:`vnrrt.search.astar`), measured between
  cell centres. Continuous paths are ~5% shorter, so 1% above it is a loose target.
* ``any_angle``: that A* path pulled taut. From each kept vertex the walk jumps to the
  furthest later path cell whose centre is visible (segment free under the exact,
  conservative test of :mod:`.collision`), and the polyline through the kept centres
  is measured. It is a tighter, still reachable target for a continuous planner
  (a feasible polyline from the start cell's centre to the goal cell's centre); it can
  exceed the true Euclidean optimum slightly where greedy shortcuts miss the best
  taut path.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from vnrrt.grid import cell_center, point_to_cell
from vnrrt.planners.collision import polyline_length, segment_free
from vnrrt.search import astar


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


def any_angle_length(occ: np.ndarray, start, goal) -> float:
    """Length of the taut A* path between the centres of the start and goal cells."""
    s, g = _cells(start, goal)
    path, _ = astar(occ, s, g)
    return polyline_length(taut_path(occ, path))


def reference_length(occ: np.ndarray, start, goal, kind: str = "astar") -> float:
    """Reference length of kind ``'astar'`` or ``'any_angle'`` (see module doc)."""
    if kind == "astar":
        return astar_length(occ, start, goal)
    if kind == "any_angle":
        return any_angle_length(occ, start, goal)
    raise ValueError(f"unknown reference {kind!r}; use 'astar' or 'any_angle'")
