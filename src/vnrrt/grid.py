"""Coordinate conventions and input validation for occupancy grids: the one place they live.

Conventions used everywhere in :mod:`vnrrt`:

* A grid is a 2-D array of shape ``(H, W)``, indexed ``grid[y, x]``: ``y`` is the row
  (down), ``x`` the column (right). Any nonzero value is an obstacle.
* Cells are written ``(x, y)``: integer column and row. Arrays of cells have shape
  ``(N, 2)`` with columns ``(x, y)``.
* A continuous point ``(x, y)`` (floats, pixel units) lies in cell
  ``(floor(x), floor(y))``, i.e. in ``grid[floor(y), floor(x)]``. The cell ``(x, y)``
  covers ``[x, x+1) x [y, y+1)`` and has its centre at ``(x + 0.5, y + 0.5)``.
* Map pixel classes (paper, Experiments/Data): 0 free, 1 obstacle, 2 start, 3 goal.
* 8-connected moves have octile costs: 1 for a straight move, sqrt(2) for a diagonal.
"""

from __future__ import annotations

import math
from typing import Final

import numpy as np

FREE: Final = 0
OBSTACLE: Final = 1
START: Final = 2
GOAL: Final = 3

SQRT2: Final = math.sqrt(2.0)

# The 8 moves as (dx, dy), indexed by the chain code stored in shards: 0..3 straight
# (E, S, W, N), 4..7 diagonal (SE, SW, NW, NE). y grows downwards.
MOVES: Final = np.array(
    [[1, 0], [0, 1], [-1, 0], [0, -1], [1, 1], [-1, 1], [-1, -1], [1, -1]], dtype=np.int64
)
MOVE_COSTS: Final = np.array([1.0] * 4 + [SQRT2] * 4)


class GridError(ValueError):
    """A grid, cell or point given to vnrrt is malformed; the message names the problem."""


class NoPathError(GridError):
    """Start and goal are not connected (by the 8-connected, no-corner-cutting graph of
    :mod:`vnrrt.search.astar`, or among the obstacles in continuous space)."""


def as_occupancy(grid: np.ndarray, name: str = "grid") -> np.ndarray:
    """Validate ``grid`` and return it as a C-contiguous ``(H, W)`` uint8 array of 0/1.

    Accepted: 2-D, at least 2x2, dtype bool or integer (nonzero = obstacle). Floats are
    refused because a float occupancy (e.g. a probability map) is ambiguous.
    """
    arr = np.asarray(grid)
    if arr.ndim != 2:
        raise GridError(f"{name} must be a 2-D (H, W) array, got shape {arr.shape}")
    if arr.shape[0] < 2 or arr.shape[1] < 2:
        raise GridError(f"{name} must be at least 2x2, got shape {arr.shape}")
    if not (arr.dtype == np.bool_ or np.issubdtype(arr.dtype, np.integer)):
        raise GridError(
            f"{name} must have a bool or integer dtype (nonzero = obstacle), got {arr.dtype}"
        )
    return np.ascontiguousarray(arr != 0, dtype=np.uint8)


def as_cell(grid: np.ndarray, cell, name: str) -> tuple[int, int]:
    """Validate an integer cell ``(x, y)`` against an occupancy grid; return it as ints.

    Raises :class:`GridError` when the cell is not two integers, lies outside the grid
    or lies on an obstacle.
    """
    arr = np.asarray(cell)
    if arr.shape != (2,) or not np.issubdtype(arr.dtype, np.integer):
        raise GridError(f"{name} must be an integer cell (x, y), got {cell!r}")
    x, y = int(arr[0]), int(arr[1])
    h, w = grid.shape
    if not (0 <= x < w and 0 <= y < h):
        raise GridError(f"{name} {(x, y)} is outside the {w}x{h} grid (x in [0,{w}), y in [0,{h}))")
    if grid[y, x]:
        raise GridError(f"{name} {(x, y)} lies on an obstacle")
    return x, y


def as_point(grid: np.ndarray, point, name: str) -> tuple[float, float]:
    """Validate a continuous point ``(x, y)`` in pixel units; return it as floats.

    The point must be finite, inside ``[0, W) x [0, H)`` and in a free cell.
    """
    try:
        arr = np.asarray(point, dtype=np.float64)
    except (TypeError, ValueError):  # not numbers: e.g. strings, ragged sequences
        arr = np.full(0, np.nan)
    if arr.shape != (2,) or not np.all(np.isfinite(arr)):
        raise GridError(f"{name} must be a finite point (x, y), got {point!r}")
    x, y = float(arr[0]), float(arr[1])
    h, w = grid.shape
    if not (0.0 <= x < w and 0.0 <= y < h):
        raise GridError(f"{name} {(x, y)} is outside the {w}x{h} grid")
    if grid[int(math.floor(y)), int(math.floor(x))]:
        raise GridError(f"{name} {(x, y)} lies in an obstacle cell")
    return x, y


def cell_center(cells: np.ndarray) -> np.ndarray:
    """Centres ``(N, 2)`` float64 of integer cells ``(N, 2)`` (x, y): cell + 0.5."""
    return np.asarray(cells, dtype=np.float64) + 0.5


def point_to_cell(points: np.ndarray) -> np.ndarray:
    """Cells ``(N, 2)`` int64 (x, y) containing continuous points ``(N, 2)`` (x, y)."""
    return np.floor(np.asarray(points, dtype=np.float64)).astype(np.int64)


def disk(radius: float) -> np.ndarray:
    """The cells within Euclidean distance ``radius`` (pixels) of a centre cell, as a
    ``(2k+1, 2k+1)`` bool stencil with ``k = floor(radius)`` and the centre at ``[k, k]``:
    offset ``(dx, dy)`` is in it when ``dx^2 + dy^2 <= radius^2``. ``radius`` 0 is the centre
    cell alone. Used for target dilation, start/goal markers and "within r px" metrics."""
    if not (radius >= 0 and math.isfinite(radius)):
        raise GridError(f"disk radius must be finite and >= 0, got {radius!r}")
    k = int(math.floor(radius))
    d = np.arange(-k, k + 1)
    return d[None, :] ** 2 + d[:, None] ** 2 <= radius * radius
