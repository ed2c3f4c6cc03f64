"""Impossible stop targets and wrongly typed references are errors naming the argument, in
plan() and Planner.solve() alike (vnrrt.planners.arguments)."""

import math

import numpy as np
import pytest

from vnrrt.planners import Planner, PlannerConfig, plan
from vnrrt.planners.arguments import check_stop_target

GRID = np.zeros((20, 20), np.uint8)
START, GOAL = (2.5, 2.5), (14.5, 7.5)  # 13 px apart in a straight line
STRAIGHT = math.hypot(12.0, 5.0)


def _calls():
    yield lambda **kw: plan(GRID, START, GOAL, **kw)
    yield lambda **kw: Planner(GRID, "rrt_star").solve(START, GOAL, **kw)


@pytest.mark.parametrize("call", list(_calls()), ids=["plan", "solve"])
@pytest.mark.parametrize("ref", [0, 0.0, 1e-9, -1.0, math.inf, math.nan, STRAIGHT * 0.99])
def test_an_optimal_target_no_path_can_meet_is_an_error(call, ref):
    with pytest.raises(ValueError, match="reference_length"):
        call(stop="optimal", reference_length=ref, seed=1)


@pytest.mark.parametrize("call", list(_calls()), ids=["plan", "solve"])
@pytest.mark.parametrize("ref", ["10", b"10", [10.0], True, None.__class__])
@pytest.mark.parametrize("stop", ["initial", "optimal"])
def test_a_reference_that_is_not_a_number_is_a_type_error_naming_it(call, ref, stop):
    with pytest.raises(TypeError, match="reference_length must be a number"):
        call(stop=stop, reference_length=ref, seed=1)


@pytest.mark.parametrize("call", list(_calls()), ids=["plan", "solve"])
@pytest.mark.parametrize("ref", [-1.0, math.inf, math.nan])
def test_an_initial_runs_recorded_reference_must_be_a_finite_length(call, ref):
    with pytest.raises(ValueError, match="reference_length must be finite and >= 0"):
        call(stop="initial", reference_length=ref, seed=1)


@pytest.mark.parametrize("call", list(_calls()), ids=["plan", "solve"])
def test_a_reachable_reference_still_plans(call):
    eps = PlannerConfig().eps
    for ref in (STRAIGHT, np.float32(STRAIGHT * 1.5), 14):  # the straight line: reachable
        r = call(stop="optimal", reference_length=ref, seed=1)
        assert r.success and STRAIGHT <= r.cost <= (1 + eps) * float(ref) + 1e-9


def test_the_check_alone():
    exact = PlannerConfig(eps=0.0)
    check_stop_target("optimal", STRAIGHT * (1 - 1e-12), START, GOAL, exact)  # rounding
    check_stop_target("initial", 0.0, START, GOAL)  # only recorded under 'initial'
    check_stop_target("optimal", None, START, GOAL)  # None: the reference is computed
    with pytest.raises(ValueError, match="below the straight-line distance"):
        check_stop_target("optimal", 12.9, START, GOAL, exact)
    # within eps below the straight line: (1 + eps) x reference reaches it, so it is accepted
    check_stop_target("optimal", STRAIGHT / 1.01, START, GOAL)  # the default eps, 0.01
    with pytest.raises(ValueError, match="below the straight-line distance"):
        check_stop_target("optimal", STRAIGHT / 1.011, START, GOAL)
    with pytest.raises(ValueError, match="below the straight-line distance"):
        check_stop_target("optimal", STRAIGHT / 1.01, START, GOAL, exact)


def test_a_reference_within_eps_below_the_straight_line_is_met_by_it():
    cfg = PlannerConfig(straight_first=True)
    ref = STRAIGHT / (1 + cfg.eps)  # (1 + eps) x ref: the straight line's length
    a = plan(GRID, START, GOAL, stop="optimal", reference_length=ref, seed=1, config=cfg)
    b = Planner(GRID, config=cfg).solve(START, GOAL, stop="optimal", reference_length=ref)
    for r in (a, b):
        assert r.success and r.cost == pytest.approx(STRAIGHT)
