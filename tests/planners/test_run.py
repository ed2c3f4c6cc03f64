"""One timed run (planners/run.py): its tree does not depend on where the compiled loop
returns (chunk ends at the bounds passed, a tree enlarged when full, a planner's arrays
reused), its times are ordered, and the time budget ends it."""

import math

import numpy as np
import pytest

from vnrrt.maps.named import named_map
from vnrrt.planners import FASTEST, Planner, PlannerConfig, plan, run
from vnrrt.planners.planner import warmup

CASES = [
    ("rrt_star", PlannerConfig(), "optimal", ()),
    ("rrt_star", FASTEST, "optimal", (1.2, 1.05)),
    ("vnrrt_star", PlannerConfig(informed=True), "optimal", (1.5,)),
    ("m_vnrrt_star", PlannerConfig(tau=0.5), "initial", ()),
    ("rrt_star", PlannerConfig(max_iterations=9000, eps=0.0), "unreachable", ()),  # fills up
    ("rrt_star", FASTEST.replace(gap_share=0.3, gap_after=100), "optimal", (1.1,)),  # gaps
    ("vnrrt_star", PlannerConfig(gap_share=0.2, gap_width=4), "initial", ()),
    # gaps and a tree that fills up: the compiled loop finds the cells again after enlarging
    (
        "rrt_star",
        PlannerConfig(max_iterations=9000, gap_share=0.3, gap_after=100, eps=0.0),
        "unreachable",
        (),
    ),
]


@pytest.mark.parametrize(("planner", "config", "stop", "factors"), CASES)
def test_a_runs_tree_does_not_depend_on_where_its_loop_returns(planner, config, stop, factors):
    """Same seed: the same iterations, nodes, checks, costs, path and trace whether the loop's
    chunks end at extra cost bounds (milestones) or not, and whether the tree starts small
    (enlarged when full) or in a planner's arrays already grown (as by an earlier run); the times
    are ordered (first solution, bounds passed, stop) and within the run."""
    warmup()
    fm = named_map("cluttered", 200)
    s, g = fm.starts[0] + 0.5, fm.goals[0] + 0.5
    heat = None if planner == "rrt_star" else np.asarray(fm.grid == 0, float)
    # the straight line at eps 0 (a turning map): a target no run meets, the budget ends it
    ref = math.dist(s, g) if stop == "unreachable" else None
    stop = "optimal" if stop == "unreachable" else stop
    ask = {"stop": stop, "seed": 7, "reference_length": ref}
    plain = plan(fm.grid, s, g, planner, heatmap=heat, config=config, **ask)
    bounds = tuple(f * plain.cost for f in factors)
    a = plan(fm.grid, s, g, planner, heatmap=heat, config=config, milestones=bounds, **ask)
    grown = Planner(fm.grid, planner, heatmap=heat, config=config)
    grown.setup.fresh().enlarge(config.max_iterations)  # as an earlier, longer run left them
    b = grown.solve(s, g, milestones=bounds, **ask)
    for r in (a, b):
        for field in ("success", "stop_reason", "cost", "iterations", "tree_size",
                      "collision_checks", "first_cost", "first_iteration"):  # fmt: skip
            assert getattr(r, field) == getattr(plain, field), field
        np.testing.assert_array_equal(r.path, plain.path)
        np.testing.assert_array_equal(r.trace_costs, plain.trace_costs)
        np.testing.assert_array_equal(r.trace_iterations, plain.trace_iterations)
    assert [m.iteration for m in a.milestones] == [m.iteration for m in b.milestones]
    times = [a.time_to_first, *(m.time for m in a.milestones if m.reached), a.time_to_stop]
    assert all(not math.isnan(t) for t in times) and times == sorted(times)
    if ref == 1.0:
        assert a.stop_reason == "max_iterations" and a.tree_size > run.FIRST_CAPACITY


def test_the_compiled_loop_stops_at_the_time_budget():
    """max_seconds ends a run that cannot meet its target, soon after the budget."""
    fm = named_map("cluttered", 200)
    s, g = fm.starts[0] + 0.5, fm.goals[0] + 0.5
    cfg = PlannerConfig(max_seconds=0.05, max_iterations=10**9, eps=0.0)  # the straight line
    r = plan(fm.grid, s, g, config=cfg, stop="optimal", reference_length=math.dist(s, g), seed=0)
    assert r.stop_reason == "max_seconds" and not r.success
    assert 0.05 <= r.time_to_stop < 1.0
