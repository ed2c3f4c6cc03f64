"""Maps of other sizes and shapes than the 200x200 training maps, through labels, the exact
optimum and the planners: MovingAI's 193x194 ``lak304d`` and its transpose (194x193), where
any mix-up of width and height, or of ``(x, y)`` and ``(row, col)``, changes an answer.
References: the published optimal lengths, the file's character counts, and the transposed
map's answers (the same lengths, the same free area)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from tests.conftest import REPO
from vnrrt.data.label import label_map
from vnrrt.grid import GridError
from vnrrt.maps.generate import FloorMap
from vnrrt.maps.movingai import read_map, read_scen
from vnrrt.planners import FASTEST, PlannerConfig, plan
from vnrrt.planners.run import gamma
from vnrrt.search import any_angle_length, any_angle_path, astar, segment_visible

MAP = REPO / "data" / "movingai" / "lak304d.map"


@pytest.fixture(scope="module")
def lak():
    grid = read_map(MAP)
    longest = sorted(read_scen(f"{MAP}.scen"), key=lambda s: (-s.optimal, s.line))[:3]
    return grid, longest


def _t(p):  # a cell or point (x, y) of the transposed map
    return p[1], p[0]


def _visible(grid, path) -> bool:
    return all(segment_visible(grid, *path[k], *path[k + 1]) for k in range(len(path) - 1))


def test_labels_and_astar_agree_with_the_published_lengths_both_ways(lak):
    grid, longest = lak
    assert grid.shape == (194, 193)  # (H, W): "height 194", "width 193"
    starts = np.array([s.start for s in longest])
    goals = np.array([s.goal for s in longest])
    labels = label_map(FloorMap(grid, starts, goals))
    for i, s in enumerate(longest):  # goal-major order: instance (goal i, start i)
        _, length = astar(grid, s.start, s.goal)
        assert labels.length[i * len(longest) + i] == pytest.approx(length, abs=1e-9)
        assert length == pytest.approx(s.optimal, abs=1e-3)  # 6 significant digits
        _, transposed = astar(np.ascontiguousarray(grid.T), _t(s.start), _t(s.goal))
        assert transposed == pytest.approx(length, abs=1e-9)


def test_the_exact_optimum_is_a_visible_path_no_longer_than_astar_both_ways(lak):
    grid, longest = lak
    gt = np.ascontiguousarray(grid.T)
    for s in longest:
        path, length = any_angle_path(grid, s.start_point, s.goal_point)
        assert any_angle_length(grid, s.start_point, s.goal_point) == length
        assert _visible(grid, path)
        assert math.dist(s.start_point, s.goal_point) <= length <= s.optimal + 1e-3
        assert length == pytest.approx(float(np.linalg.norm(np.diff(path, axis=0), axis=1).sum()))
        assert any_angle_length(gt, _t(s.start_point), _t(s.goal_point)) == pytest.approx(length)


def test_the_near_radius_comes_from_the_maps_free_area():
    grid = read_map(MAP)
    free = sum(row.count(".") for row in MAP.read_text().splitlines()[4:])  # '.' only here
    cfg = PlannerConfig()
    expected = 2.0 * math.sqrt(1.5) * math.sqrt(free / math.pi)  # RRT*'s bound, d = 2
    assert gamma(grid, cfg) == pytest.approx(expected)
    assert gamma(np.ascontiguousarray(grid.T), cfg) == pytest.approx(expected)


@pytest.mark.parametrize("transposed", [False, True])
def test_planners_reach_one_percent_of_the_exact_optimum_on_a_non_square_map(lak, transposed):
    grid, longest = lak
    s = longest[0]
    start, goal = s.start_point, s.goal_point
    if transposed:
        grid, start, goal = np.ascontiguousarray(grid.T), _t(start), _t(goal)
    exact = any_angle_length(grid, start, goal)
    result = plan(grid, start, goal, stop="optimal", reference_length=exact, seed=0,
                  config=FASTEST)  # fmt: skip
    assert result.success and result.cost <= 1.01 * exact + 1e-9
    assert _visible(grid, result.path)
    assert tuple(result.path[0]) == start and tuple(result.path[-1]) == goal
    heat = np.random.default_rng(0).random(grid.shape)
    sampled = plan(grid, start, goal, "vnrrt_star", heatmap=heat, seed=0, config=FASTEST)
    assert sampled.success and _visible(grid, sampled.path)
    with pytest.raises(GridError, match="heatmap has shape"):  # (W, H): refused
        plan(grid, start, goal, "vnrrt_star", heatmap=heat.T, seed=0, config=FASTEST)


def test_heatmap_metrics_of_a_perfect_heatmap_on_a_non_square_map(lak):
    import torch

    from vnrrt.data.targets import label_masks
    from vnrrt.model.metrics import metric_collection
    from vnrrt.search import path_vertices

    grid, longest = lak
    for g in (grid, np.ascontiguousarray(grid.T)):
        s = longest[0]
        start, goal = (s.start, s.goal) if g is grid else (_t(s.start), _t(s.goal))
        path, _ = astar(g, start, goal)
        masks = label_masks(path, path_vertices(path), g.shape)
        assert all(m.shape == g.shape for m in masks.values())
        metrics = metric_collection(3.0, 0.5, 2.0, 3.0, (0.5,), with_target=False)
        metrics.update(preds=torch.from_numpy(masks["vertices"].astype(np.float32))[None],
                       **{k: torch.from_numpy(v)[None] for k, v in masks.items()})  # fmt: skip
        got = {k: float(v) for k, v in metrics.compute().items()}
        assert got["mass_near_vertex"] == pytest.approx(1.0)
        assert got["vertex_recall"] == pytest.approx(1.0)
        assert got["mass_near_vertex_uniform"] < 0.05  # a small share of a large map
