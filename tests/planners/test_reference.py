"""Reference lengths (A*, exact any-angle, taut approximation) and the planner config file."""

import math

import numpy as np
import pytest
from omegaconf import OmegaConf

from vnrrt.config import section
from vnrrt.planners import (
    PlannerConfig,
    PlannerConfigError,
    any_angle_length,
    any_angle_path,
    astar_length,
    path_free,
    polyline_length,
    reference_length,
    taut_length,
    taut_path,
)
from vnrrt.search import astar


def test_empty_map_any_angle_is_straight_line():
    g = np.zeros((50, 60), np.uint8)
    s, e = (3.5, 4.5), (51.5, 40.5)
    assert any_angle_length(g, s, e) == pytest.approx(math.dist(s, e))
    assert taut_length(g, s, e) == pytest.approx(math.dist(s, e))
    assert astar_length(g, s, e) > math.dist(s, e)


@pytest.mark.parametrize("seed", range(6))
def test_taut_path_is_free_and_between_bounds(seed):
    rng = np.random.default_rng(seed)
    g = (rng.random((40, 40)) < 0.2).astype(np.uint8)
    g[:3, :3] = g[-3:, -3:] = 0
    cells, length = astar(g, (1, 1), (38, 38))  # these seeds give connected maps
    taut = taut_path(g, cells)
    assert path_free(g, taut)
    assert np.array_equal(taut[0], [1.5, 1.5]) and np.array_equal(taut[-1], [38.5, 38.5])
    assert math.dist(taut[0], taut[-1]) - 1e-9 <= polyline_length(taut) <= length + 1e-9
    s, e = (1.5, 1.5), (38.5, 38.5)
    assert reference_length(g, s, e, "taut") == taut_length(g, s, e) == polyline_length(taut)
    exact = reference_length(g, s, e, "any_angle")
    assert exact == any_angle_length(g, s, e) == any_angle_path(g, s, e)[1]
    assert math.dist(s, e) - 1e-9 <= exact <= polyline_length(taut) + 1e-9
    assert reference_length(g, s, e) == reference_length(g, s, e, "astar") == length


def test_taut_is_an_approximation_from_above():
    """Grazing a block's corner: the exact length is the infimum of free paths (sqrt 2),
    the taut path through cell centres may not touch the corner and goes round (2)."""
    g = np.zeros((6, 6), np.uint8)
    g[2, 2] = 1
    s, e = (2.5, 3.5), (3.5, 2.5)
    assert any_angle_length(g, s, e) == pytest.approx(math.sqrt(2))
    assert taut_length(g, s, e) == reference_length(g, s, e, "taut") == pytest.approx(2.0)
    assert astar_length(g, s, e) == pytest.approx(2.0)


def test_unknown_reference_kind():
    with pytest.raises(ValueError, match="unknown reference"):
        reference_length(np.zeros((4, 4), np.uint8), (0.5, 0.5), (3.5, 3.5), "theta")


def test_config_file_validates_and_equals_defaults(repo):
    node = OmegaConf.load(repo / "conf" / "planner" / "default.yaml")
    cfg = section({"planner": node}, "planner", PlannerConfig)
    assert cfg == PlannerConfig()
    assert cfg.mix == 0.5 and cfg.eps == 0.01 and cfg.taus == [0.5, 0.9, 0.99]


@pytest.mark.parametrize(
    "change",
    [{"radius_mode": "grow"}, {"reference": "theta"}, {"mix": 1.5}, {"gamma": 0.0}, {"eps": -1}],
)
def test_bad_settings_are_named(change):
    with pytest.raises(PlannerConfigError, match=next(iter(change))):
        PlannerConfig().replace(**change)
