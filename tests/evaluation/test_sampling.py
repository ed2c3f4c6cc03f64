"""The one obstacle rule, applied to every heatmap source and to the uniform part of every
sampler: checked through the samples the planners' own sampler draws."""

import numpy as np
import pytest

from vnrrt.evaluation.keys import ConfigKey
from vnrrt.evaluation.sampling import build_sampler, free_rule
from vnrrt.evaluation.sources import allowed_cells
from vnrrt.planners import PlannerConfig, draw


@pytest.fixture
def walled():
    """A 40x40 map with a thick wall, and a network heatmap whose mass sits mostly on it."""
    grid = np.zeros((40, 40), np.uint8)
    grid[:, 15:25] = 1
    heat = np.full((40, 40), 0.01)
    heat[:, 15:25] = 0.9  # a poor network: most of its mass on the wall
    return grid, heat


def on_obstacles(grid, points) -> float:
    cells = np.floor(points).astype(int)
    return float(grid[cells[:, 1], cells[:, 0]].mean())


@pytest.mark.parametrize("planner", ["rrt_star", "vnrrt_star", "m_vnrrt_star"])
def test_the_free_rule_draws_no_sample_on_obstacles_and_the_default_does(walled, planner):
    grid, heat = walled
    key = ConfigKey(planner, 0.5 if planner == "m_vnrrt_star" else None,
                    None if planner == "rrt_star" else "net")  # fmt: skip
    config = PlannerConfig(tau=0.5)
    shares = {}
    for free in (False, True):
        allowed = allowed_cells(grid, free)
        h = None if planner == "rrt_star" else np.where(allowed, heat, 0.0)
        sampler, _, _ = build_sampler(key, h, allowed, config, free)
        shares[free] = on_obstacles(grid, draw(sampler, 4000, seed=1))
    assert shares[True] == 0.0  # free cells only: heatmap and uniform part alike
    assert shares[False] > 0.2  # every cell: the wall (a quarter of the map) gets samples


def test_the_free_rule_keeps_the_mix_of_heatmap_and_uniform_draws(walled):
    """On free cells, a sampler still draws from its heatmap with probability mix and
    uniformly otherwise: a heatmap on one free corner gets about mix of the samples."""
    grid, _ = walled
    heat = np.zeros((40, 40))
    heat[:5, :5] = 1.0
    allowed = allowed_cells(grid, True)
    key = ConfigKey("vnrrt_star", source="net").with_mix(0.25)
    sampler, used, _ = build_sampler(key, heat, allowed, PlannerConfig(), True)
    corner = (draw(sampler, 8000, seed=3) < 5).all(axis=1).mean()
    uniform_corner = 25 / allowed.sum()
    assert used.mix == 1.0  # one mixture, drawn with probability 1
    assert corner == pytest.approx(0.25 + 0.75 * uniform_corner, abs=0.02)


def test_a_key_flips_the_default_rule():
    assert free_rule(ConfigKey("rrt_star"), False) is False
    assert free_rule(ConfigKey("rrt_star").with_free(), False) is True
    assert free_rule(ConfigKey("rrt_star").with_free(), True) is False
