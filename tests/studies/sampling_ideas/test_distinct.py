"""The distinct-cell rule: the shrinking radius's "stays at eta" condition against a brute
force over tree sizes and the planner's own gamma; two cells judged the same give identical
runs (iterations, cost) seed for seed, two judged distinct do not; the regime grid runs each
distinct setting once, and the analysis counts cells whose runs kept the radius at eta as
the fixed-radius cell."""

import math

import numpy as np
import pandas as pd
import pytest

from vnrrt.evaluation.config import RegimeConfig
from vnrrt.planners import PlannerConfig, plan
from vnrrt.planners.run import gamma as planner_gamma
from vnrrt.search import any_angle_path
from vnrrt.studies.sampling_ideas.design import cell_of_label, protocol_settings, regime_cells
from vnrrt.studies.sampling_ideas.distinct import (
    cell_key,
    effective_keys,
    groups,
    rrt_gamma,
    stays_at_eta,
)

GRID = np.zeros((40, 60), np.uint8)
GRID[0:30, 30] = 1  # a wall hanging from the top: the path turns below it
START, GOAL = (5.5, 5.5), (55.5, 5.5)
BUDGET = 400  # iterations: tree sizes up to 402


@pytest.mark.parametrize("gamma", [5.0, 20.0, 66.0, 200.0])
@pytest.mark.parametrize("eta", [2.0, 5.0, 10.0])
def test_stays_at_eta_equals_a_brute_force_over_tree_sizes(gamma, eta):
    n = np.arange(1, BUDGET + 3)
    m = np.maximum(n, 2)
    radius = np.minimum(gamma * np.sqrt(np.log(m) / m), eta)
    assert stays_at_eta(gamma, eta, BUDGET + 2) == bool(np.all(radius == eta))
    assert not stays_at_eta(gamma, math.inf, BUDGET + 2)


def test_the_bound_is_the_planners_gamma():
    for factor in (1.0, 0.1):
        cfg = PlannerConfig(gamma_factor=factor)
        free = int(GRID.size - GRID.sum())
        assert rrt_gamma(free, factor) == pytest.approx(planner_gamma(GRID, cfg), rel=1e-12)


def _runs(over: dict) -> list[tuple[int, float, int]]:
    """(iterations, cost, tree size) of 6 seeded runs to within 10% of the exact optimum."""
    _, exact = any_angle_path(GRID, START, GOAL)
    cfg = PlannerConfig(max_iterations=BUDGET, eps=0.0).replace(**over)
    out = []
    for seed in range(6):
        r = plan(GRID, START, GOAL, config=cfg, seed=seed, stop="optimal",
                 reference_length=1.1 * exact)  # fmt: skip
        out.append((r.iterations, r.cost, r.tree_size))
    return out


def test_cells_judged_the_same_run_the_same_and_distinct_ones_do_not():
    free = int(GRID.size - GRID.sum())
    shrinking = {"eta": 5.0, "radius_mode": "shrinking", "gamma_factor": 1.0, "goal_radius": None}
    small = {**shrinking, "gamma_factor": 0.1}
    fixed = {"eta": 5.0, "radius_mode": "fixed", "fixed_radius": 5.0, "goal_radius": None}
    stays = stays_at_eta(rrt_gamma(free, 1.0), 5.0, BUDGET + 2)
    assert stays and not stays_at_eta(rrt_gamma(free, 0.1), 5.0, BUDGET + 2)
    assert cell_key(shrinking, stays) == cell_key(fixed) != cell_key(small)
    assert _runs(shrinking) == _runs(fixed)  # judged the same: run for run
    assert _runs(small) != _runs(fixed)  # judged distinct: not
    unlimited = {"eta": math.inf, "radius_mode": "shrinking", "gamma_factor": 1.0}
    eta_goal, inf_goal = {**unlimited, "goal_radius": None}, {**unlimited, "goal_radius": math.inf}
    assert cell_key(eta_goal) == cell_key(inf_goal)  # the goal radius is moot at eta = inf
    assert _runs(eta_goal) == _runs(inf_goal)
    finite = [{**shrinking, "goal_radius": g} for g in (None, math.inf)]
    assert cell_key(finite[0]) != cell_key(finite[1])


def test_the_analysis_counts_a_cell_whose_runs_kept_eta_as_the_fixed_cell():
    free = {0: int(GRID.size - GRID.sum())}
    cells = {"eta=5 radius=fixed1 goal=eta": cell_of_label("eta=5 radius=fixed1 goal=eta"),
             "eta=5 radius=shrinking goal=eta": cell_of_label("eta=5 radius=shrinking goal=eta"),
             "eta=5 radius=shrinking*0.1 goal=eta":
                 cell_of_label("eta=5 radius=shrinking*0.1 goal=eta")}  # fmt: skip
    rows = [{"regime": c, "instance": 0, "tree_size": size}
            for c, over in cells.items() for _, _, size in _runs(over)]  # fmt: skip
    keys = effective_keys(pd.DataFrame(rows), cells, free)
    assert groups(keys) == {
        "eta=5 radius=fixed1 goal=eta": ["eta=5 radius=fixed1 goal=eta",
                                         "eta=5 radius=shrinking goal=eta"],
        "eta=5 radius=shrinking*0.1 goal=eta": ["eta=5 radius=shrinking*0.1 goal=eta"],
    }  # fmt: skip
    assert len(groups(effective_keys(pd.DataFrame(rows), cells, None))) == 3  # settings only


def test_the_grid_runs_each_distinct_setting_once():
    rc = RegimeConfig(etas=[10.0, math.inf], radius_modes=["shrinking"], gamma_factors=[1.0],
                      goal_radii=[None, math.inf, 10.0])  # fmt: skip
    cells = regime_cells(rc, protocol_settings(PlannerConfig(eta=7.0)))
    # eta 10: goal=eta and goal=10 are one radius; eta inf: every goal radius is inf
    assert sorted(cells) == ["eta=10 radius=shrinking goal=eta",
                             "eta=10 radius=shrinking goal=inf",
                             "eta=inf radius=shrinking goal=eta"]  # fmt: skip
    for label, over in cells.items():
        assert cell_of_label(label) == over
