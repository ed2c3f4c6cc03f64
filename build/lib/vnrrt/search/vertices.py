"""Vertices (turning points) of an 8-connected grid path, following the paper's rule.

The paper (Method, Ground Truth) defines, for a path ``x_0 .. x_T``::

    X_vertex = { x_i | D(x_i - x_{i-1}) and D(x_i - x_{i-2}) and D(x_i - x_{i-3}) }

with ``D`` "a change in direction at that step size". Our reading, stated precisely:

* For step size ``k`` the incoming vector is ``a = x_i - x_{i-k}`` and the outgoing one
  ``b = x_{i+k} - x_i``. As in the formula, both must exist: points closer than
  ``max(k)`` steps to the start or the goal are not interior vertices (they lie within
  2 cells of an endpoint, which is a vertex anyway). Truncated windows would otherwise
  mark the first point of every zigzag that starts at an endpoint.
* The direction *does not change* at step ``k`` when ``a`` and ``b`` point the same way
  (``cross(a, b) == 0`` and ``dot(a, b) > 0``); for equal step counts on optimal paths
  this is ``a == b``.
* ``x_i`` is a vertex when the direction changes at *all three* step sizes 1, 2 and 3.
  Hence (Fig. 2 of the paper) points on straight 0/90/45 degree runs (no change at k=1),
  on zigzags alternating two moves, e.g. E,NE,E,NE (no change at k=2), and on zigzags
  repeating three moves, e.g. E,E,NE (no change at k=3), are not vertices.
* The start ``x_0`` and the goal ``x_T`` are always vertices.
"""

from __future__ import annotations

import numpy as np
from numba import njit

STEP_SIZES = (1, 2, 3)


@njit(cache=True)
def vertex_flags(path: np.ndarray, steps: np.ndarray) -> np.ndarray:
    """Boolean flags ``(T+1,)``: True where ``path[i]`` is a vertex (rule in module doc)."""
    n = path.shape[0]
    flags = np.zeros(n, np.bool_)
    flags[0] = True
    flags[n - 1] = True
    for i in range(1, n - 1):
        changed_all = True
        for k in steps:
            p, q = i - k, i + k
            if p < 0 or q > n - 1:
                changed_all = False
                break
            ax, ay = path[i, 0] - path[p, 0], path[i, 1] - path[p, 1]
            bx, by = path[q, 0] - path[i, 0], path[q, 1] - path[i, 1]
            if ax * by - ay * bx == 0 and ax * bx + ay * by > 0:
                changed_all = False
                break
        flags[i] = changed_all
    return flags


def vertex_indices(path: np.ndarray, steps=STEP_SIZES) -> np.ndarray:
    """Indices ``(K,)`` int64 into ``path`` ``(T+1, 2)`` of its vertices, in path order."""
    arr = np.ascontiguousarray(path, dtype=np.int64)
    if arr.ndim != 2 or arr.shape[1] != 2 or len(arr) < 1:
        raise ValueError(f"path must be a non-empty (T+1, 2) array of cells, got {arr.shape}")
    if len(arr) == 1:
        return np.zeros(1, np.int64)
    return np.flatnonzero(vertex_flags(arr, np.asarray(steps, np.int64)))


def path_vertices(path: np.ndarray) -> np.ndarray:
    """Vertices ``(K, 2)`` int64 (x, y) of an 8-connected path ``(T+1, 2)``; start and goal
    included. See the module docstring for the rule."""
    arr = np.asarray(path, dtype=np.int64)
    return arr[vertex_indices(arr)]


def path_mask(path: np.ndarray, shape: tuple[int, int]) -> np.ndarray:
    """Boolean ``(H, W)`` mask of all cells of ``path`` ``(T+1, 2)`` (x, y): the NRRT* target."""
    mask = np.zeros(shape, dtype=bool)
    arr = np.asarray(path, dtype=np.int64)
    mask[arr[:, 1], arr[:, 0]] = True
    return mask
