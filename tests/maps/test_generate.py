"""Random floor maps and the five named maps: validity, reachability, determinism."""

import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from vnrrt.maps.config import DataConfig
from vnrrt.maps.generate import MapGenerationError, generate_map, map_rng
from vnrrt.maps.named import NAMES, named_map
from vnrrt.maps.shapes import draw_shape
from vnrrt.search import astar


@given(st.integers(0, 10**6))
def test_random_map_endpoints_are_free_distinct_far_and_reachable(map_id):
    cfg = DataConfig()
    fm = generate_map(map_rng(0, map_id), cfg)
    assert fm.grid.shape == (200, 200) and fm.grid.dtype == np.uint8
    assert set(np.unique(fm.grid)) <= {0, 1}
    assert fm.starts.shape == (12, 2) and fm.goals.shape == (12, 2)
    for cells in (fm.starts, fm.goals):
        assert np.all(fm.grid[cells[:, 1], cells[:, 0]] == 0)
        assert len({tuple(c) for c in cells}) == len(cells)
    d = np.sqrt(((fm.starts[:, None] - fm.goals[None]) ** 2).sum(-1))
    assert d.min() >= cfg.min_start_goal_distance
    astar(fm.grid, fm.starts[map_id % 12], fm.goals[(map_id // 12) % 12])  # raises if cut off


def test_maps_are_deterministic_per_seed_and_id_and_vary():
    cfg = DataConfig()
    a, b = generate_map(map_rng(7, 3), cfg), generate_map(map_rng(7, 3), cfg)
    assert np.array_equal(a.grid, b.grid) and np.array_equal(a.starts, b.starts)
    c = generate_map(map_rng(7, 4), cfg)
    assert not np.array_equal(a.grid, c.grid)


def test_obstacle_count_range_is_respected():
    few = DataConfig(n_obstacles=[0, 0])
    assert generate_map(map_rng(0, 1), few).grid.sum() == 0
    many = DataConfig(n_obstacles=[30, 30])
    assert generate_map(map_rng(0, 1), many).grid.mean() > 0.1


@pytest.mark.parametrize(
    ("kind", "area", "perimeter"),
    [
        ("circle", math.pi * 20**2, 2 * math.pi * 20),
        ("square", 40 * 40, 4 * 40),
        ("bar", 80 * 6, 2 * (80 + 6)),
        ("u_shape", 3 * 40 * 6 - 2 * 36, 2 * 40 + 4 * 40 - 2 * 6),
    ],
)
def test_each_shape_draws_its_area(kind, area, perimeter):
    """Rasterised area ~ area + half the perimeter (boundary pixels are filled)."""
    canvas = np.zeros((200, 200), np.uint8)
    draw_shape(canvas, kind, np.array([100.0, 100.0]), 40.0, 0.7, 6.0, np.random.default_rng(0))
    assert int(canvas.sum()) == pytest.approx(area + perimeter / 2, rel=0.15)


def test_triangles_are_random_but_bounded():
    areas = []
    for seed in range(5):
        canvas = np.zeros((200, 200), np.uint8)
        draw_shape(canvas, "triangle", np.array([100.0, 100.0]), 40.0, 0.0, 6.0,
                   np.random.default_rng(seed))  # fmt: skip
        areas.append(int(canvas.sum()))
    assert len(set(areas)) > 1 and all(150 < a < 800 for a in areas)


def test_impossible_config_gives_a_clear_error():
    cfg = DataConfig(min_start_goal_distance=500.0, max_attempts=3)
    with pytest.raises(MapGenerationError, match="min_start_goal_distance"):
        generate_map(map_rng(0, 0), cfg)


def test_named_maps_are_fixed_ordered_by_difficulty_and_have_narrow_passages():
    lengths, straight = [], []
    for name in NAMES:
        fm = named_map(name)
        assert np.array_equal(fm.grid, named_map(name).grid)
        _, length = astar(fm.grid, fm.starts[0], fm.goals[0])
        lengths.append(length)
        straight.append(float(np.hypot(*(fm.goals[0] - fm.starts[0]))))
    detour = np.array(lengths) / np.array(straight)
    assert detour[0] < 1.1  # open: nearly straight
    assert detour[2] > 2.0 and detour[3] > 2.0 and detour[4] > 3.0  # hard ones: long detours
    grid = named_map("narrow_passage").grid
    column = grid[:, 100]
    assert (column == 0).sum() <= 5  # one gap of a few cells through the wall
    with pytest.raises(ValueError, match="unknown named map"):
        named_map("nope")
