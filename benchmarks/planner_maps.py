"""The planner benchmark's maps: a development set (tuned on) and a held-out set (not).

Every instance is ``(name, grid, start, goal)``: a 200x200 uint8 occupancy (nonzero =
obstacle, ``grid[y, x]``) and continuous ``(x, y)`` endpoints in pixels, connected.

* :func:`dev_instances`: the five named maps, three walls maps with narrow gaps, a bug trap,
  an empty map and random maps of the data generator (the set of the earlier benchmark runs,
  used while tuning our planners).
* :func:`held_out_instances`: maps written before the tuning started and never run during it:
  single-cell gaps, a cup trap, a comb of walls, walls maps and random maps from other seeds.
  Its results are reported apart.
"""

from __future__ import annotations

import math

import numpy as np

from vnrrt.maps.config import DataConfig
from vnrrt.maps.generate import generate_map, largest_free_region, map_rng
from vnrrt.maps.named import NAMES, named_map
from vnrrt.planners.collision import point_free

SIZE = 200
Instance = tuple[str, np.ndarray, tuple[float, float], tuple[float, float]]


def walls(rng: np.random.Generator, size: int = SIZE) -> np.ndarray:
    """Two or three vertical walls 3 px thick, each with a 3-6 px gap (every other wall a
    second, 8 px gap)."""
    g = np.zeros((size, size), np.uint8)
    for i, x in enumerate(np.linspace(0, size, rng.integers(2, 4) + 2)[1:-1].astype(int)):
        gap = rng.integers(3, 7)  # a narrow gap, 3..6 px
        y = rng.integers(10, size - 10 - gap)
        g[:, x : x + 3] = 1
        g[y : y + gap, x : x + 3] = 0
        if i % 2:
            y2 = (y + size // 2) % (size - 20) + 5
            g[y2 : y2 + 8, x : x + 3] = 0
    return g


def bug_trap(size: int = SIZE) -> np.ndarray:
    """A C around the start at the centre, open to the left, the goal to the right."""
    g = np.zeros((size, size), np.uint8)
    g[60:140, 136:140] = 1  # the wall between start and goal
    g[60:64, 60:140] = 1
    g[136:140, 60:140] = 1
    return g


def far_pair(rng: np.random.Generator, g: np.ndarray, min_dist: float) -> tuple[tuple, tuple]:
    """Two cell centres at least ``min_dist`` px apart, both free in ``g``."""
    free = np.argwhere(g == 0)[:, ::-1] + 0.5
    while True:
        s, e = free[rng.integers(len(free), size=2)]
        if math.dist(s, e) >= min_dist and point_free(g, s) and point_free(g, e):
            return tuple(s), tuple(e)


def random_instances(rng, map_seed: int, n: int, prefix: str) -> list[Instance]:
    """``n`` maps of the data generator (``map_rng(map_seed, i)``), endpoints at least 0.4 x
    the map size apart in the largest free region."""
    out = []
    for i in range(n):
        fm = generate_map(map_rng(map_seed, i), DataConfig(size=SIZE))
        outside = (~largest_free_region(fm.grid)).astype(np.uint8)  # start/goal connected
        s, e = far_pair(rng, outside, 0.4 * SIZE)
        out.append((f"{prefix}{i}", fm.grid, s, e))
    return out


def dev_instances(n_random: int = 12, seed: int = 0) -> list[Instance]:
    """The development set (see module doc): 10 fixed maps and ``n_random`` random ones."""
    out = []
    for name in NAMES:
        fm = named_map(name, SIZE)
        out.append((name, fm.grid, tuple(fm.starts[0] + 0.5), tuple(fm.goals[0] + 0.5)))
    rng = np.random.default_rng(seed)
    for k in range(3):
        out.append((f"walls{k}", walls(rng), (5.5, SIZE / 2 + 0.5), (SIZE - 5.5, SIZE / 2 + 0.5)))
    out.append(("bug_trap", bug_trap(), (100.5, 100.5), (190.5, 100.5)))
    empty = np.zeros((SIZE, SIZE), np.uint8)
    out.append(("empty", empty, (5.5, 5.5), (SIZE - 5.5, SIZE - 5.5)))
    return out + random_instances(rng, seed + 1, n_random, "random")


def slits(rng: np.random.Generator, n_walls: int) -> np.ndarray:
    """``n_walls`` vertical walls 2 px thick across the map, each with a one-cell gap."""
    g = np.zeros((SIZE, SIZE), np.uint8)
    for x in np.linspace(0, SIZE, n_walls + 2)[1:-1].astype(int):
        g[:, x : x + 2] = 1
        g[rng.integers(20, SIZE - 20), x : x + 2] = 0
    return g


def cup() -> np.ndarray:
    """A cup open upwards around the start; the goal lies below it."""
    g = np.zeros((SIZE, SIZE), np.uint8)
    g[50:130, 50:54] = 1
    g[50:130, 146:150] = 1
    g[126:130, 50:150] = 1
    return g


def comb() -> np.ndarray:
    """Five walls hanging from the top and rising from the bottom in turn, 6 px gaps at
    alternate ends: a zigzag corridor."""
    g = np.zeros((SIZE, SIZE), np.uint8)
    for i, x in enumerate(range(30, 180, 30)):
        if i % 2:
            g[6:, x : x + 3] = 1
        else:
            g[: SIZE - 6, x : x + 3] = 1
    return g


def held_out_instances(n_random: int = 8, seed: int = 0) -> list[Instance]:
    """The held-out set (see module doc): 6 crafted maps and ``n_random`` random ones."""
    rng = np.random.default_rng(seed + 1000)
    mid = SIZE / 2 + 0.5
    out = [
        ("slit", slits(rng, 1), (5.5, mid), (SIZE - 5.5, mid)),
        ("slits3", slits(rng, 3), (5.5, 20.5), (SIZE - 5.5, SIZE - 20.5)),
        ("cup", cup(), (100.5, 100.5), (100.5, 190.5)),
        ("comb", comb(), (10.5, 10.5), (SIZE - 10.5, SIZE - 10.5)),
    ]
    for k in range(2):
        out.append((f"walls_h{k}", walls(rng), (5.5, 30.5), (SIZE - 5.5, SIZE - 30.5)))
    return out + random_instances(rng, seed + 1001, n_random, "random_h")
