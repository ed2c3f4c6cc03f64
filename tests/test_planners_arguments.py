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
def test_a_reachable_reference_still_plans(call):
    eps = PlannerConfig().eps
    for ref in (STRAIGHT, np.float32(STRAIGHT * 1.5), 14):  # the straight line: reachable
        r = call(stop="optimal", reference_length=ref, seed=1)
        assert r.success and STRAIGHT <= r.cost <= (1 + eps) * float(ref) + 1e-9


def test_the_check_alone():
    check_stop_target("optimal", STRAIGHT * (1 - 1e-12), START, GOAL)  # rounding: accepted
    check_stop_target("initial", 0.0, START, GOAL)  # only recorded under 'initial'
    check_stop_target("optimal", None, START, GOAL)  # None: the reference is computed
    check_stop_target("optimal", 20, "not a point", GOAL)  # left to the endpoints' checks
    with pytest.raises(ValueError, match="below the straight-line distance"):
        check_stop_target("optimal", 12.9, START, GOAL)
