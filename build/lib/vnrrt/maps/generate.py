"""Random floor maps with start and goal cells (paper, Experiments/Data).

A map is an ``(S, S)`` uint8 occupancy grid (1 = obstacle, 0 = free; :mod:`vnrrt.grid`)
holding a random number of obstacles of random kind, size, orientation and position.
Each map carries ``n_starts`` start cells and ``n_goals`` goal cells, all in the largest
connected free region (so every start reaches every goal) and every start at least
``min_start_goal_distance`` pixels (Euclidean) from every goal. Every start x goal pair
is one planning instance.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import cv2
import numpy as np

from vnrrt.maps.config import DataConfig
from vnrrt.maps.shapes import draw_shape


class MapGenerationError(RuntimeError):
    """No valid map was found within ``max_attempts``; the message says why."""


@dataclass(frozen=True)
class FloorMap:
    """One base map: ``grid`` (S, S) uint8, ``starts`` (n_starts, 2) and ``goals``
    (n_goals, 2) int64 cells (x, y)."""

    grid: np.ndarray
    starts: np.ndarray
    goals: np.ndarray


def map_rng(seed: int, map_id: int) -> np.random.Generator:
    """The generator of one map, derived from (global seed, global map id) only."""
    return np.random.default_rng(np.random.SeedSequence([seed, map_id, 0x6D6170]))


def draw_obstacles(rng: np.random.Generator, cfg: DataConfig) -> np.ndarray:
    """An ``(S, S)`` uint8 grid with ``cfg.n_obstacles`` random obstacles (1) on free (0)."""
    grid = np.zeros((cfg.size, cfg.size), np.uint8)
    n = int(rng.integers(cfg.n_obstacles[0], cfg.n_obstacles[1] + 1))
    for _ in range(n):
        kind = cfg.shapes[int(rng.integers(len(cfg.shapes)))]
        center = rng.uniform(0, cfg.size, 2)
        size = rng.uniform(*cfg.obstacle_size)
        width = rng.uniform(*cfg.bar_width)
        draw_shape(grid, kind, center, size, rng.uniform(0, 2 * math.pi), width, rng)
    return grid


def largest_free_region(grid: np.ndarray) -> np.ndarray:
    """Boolean ``(H, W)`` mask of the largest 4-connected free region.

    4-connectivity equals connectivity in the 8-connected no-corner-cutting graph of
    :mod:`vnrrt.search.astar` (a permitted diagonal always has a straight detour).
    """
    n, labels, stats, _ = cv2.connectedComponentsWithStats(
        (grid == 0).astype(np.uint8), connectivity=4
    )
    if n <= 1:
        return np.zeros(grid.shape, bool)
    biggest = 1 + int(np.argmax(stats[1:, cv2.CC_STAT_AREA]))
    return labels == biggest


def pick_endpoints(
    rng: np.random.Generator, region: np.ndarray, cfg: DataConfig
) -> tuple[np.ndarray, np.ndarray] | None:
    """Goals uniformly in ``region``, then starts far enough from all goals; None if too few.

    Returns ``(starts, goals)`` int64 ``(n, 2)`` cells (x, y).
    """
    ys, xs = np.nonzero(region)
    if len(xs) < cfg.n_goals + cfg.n_starts:
        return None
    pick = rng.choice(len(xs), cfg.n_goals, replace=False)
    goals = np.stack([xs[pick], ys[pick]], axis=1).astype(np.int64)
    h, w = region.shape
    d2 = np.full((h, w), np.iinfo(np.int64).max)
    for gx, gy in goals:  # squared distance to the nearest goal, exact in integers
        d2 = np.minimum(d2, (np.arange(h)[:, None] - gy) ** 2 + (np.arange(w)[None, :] - gx) ** 2)
    far_y, far_x = np.nonzero(region & (d2 >= cfg.min_start_goal_distance**2))
    if len(far_x) < cfg.n_starts:
        return None
    pick = rng.choice(len(far_x), cfg.n_starts, replace=False)
    starts = np.stack([far_x[pick], far_y[pick]], axis=1).astype(np.int64)
    return starts, goals


def generate_map(rng: np.random.Generator, cfg: DataConfig) -> FloorMap:
    """Draw maps from ``rng`` until one has a large enough free region and valid endpoints.

    Raises :class:`MapGenerationError` after ``cfg.max_attempts`` failures (the config
    asks for too many obstacles or too large a start-goal distance).
    """
    for _ in range(cfg.max_attempts):
        grid = draw_obstacles(rng, cfg)
        region = largest_free_region(grid)
        if region.sum() < cfg.min_free_fraction * grid.size:
            continue
        picked = pick_endpoints(rng, region, cfg)
        if picked is not None:
            return FloorMap(grid, *picked)
    raise MapGenerationError(
        f"no valid map in {cfg.max_attempts} attempts: free region below "
        f"{cfg.min_free_fraction:.0%} or too few starts {cfg.min_start_goal_distance} px from "
        "all goals; lower data.n_obstacles / data.min_start_goal_distance"
    )
