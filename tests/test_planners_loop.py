"""The run's loop in one compiled call (planners/loop.py) against its Python twin
(run.drive_python), and the compiled clock against time.perf_counter."""

import math
import time

import numpy as np
import pytest

from vnrrt.maps.named import named_map
from vnrrt.planners import FASTEST, PlannerConfig, clock, plan, run
from vnrrt.planners.api import warmup

pytestmark = pytest.mark.skipif(not clock.IN_KERNEL, reason="the compiled clock is 64-bit Linux")


def test_the_compiled_clock_is_perf_counters():
    """monotonic() read between two perf_counter() reads lies between them (same clock)."""
    clock.monotonic()
    for _ in range(100):
        a = time.perf_counter()
        b = clock.monotonic()
        c = time.perf_counter()
        assert a <= b <= c


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
def test_the_compiled_loop_grows_the_same_tree_as_the_python_loop(
    monkeypatch, planner, config, stop, factors
):
    """Same seed: the same iterations, nodes, checks, costs, path and trace from both loops
    (the tree enlarged in between when it fills up); the compiled loop's times are ordered
    (first solution, bounds passed, stop) and within the run."""
    warmup()
    fm = named_map("cluttered", 200)
    s, g = fm.starts[0] + 0.5, fm.goals[0] + 0.5
    heat = None if planner == "rrt_star" else np.asarray(fm.grid == 0, float)
    # the straight line at eps 0 (a turning map): a target no run meets, the budget ends it
    ref = math.dist(s, g) if stop == "unreachable" else None
    stop = "optimal" if stop == "unreachable" else stop
    results = {}
    for compiled in (True, False):
        monkeypatch.setattr(clock, "IN_KERNEL", compiled)
        r0 = plan(fm.grid, s, g, planner, heatmap=heat, config=config, stop=stop, seed=7,
                  reference_length=ref)  # fmt: skip
        bounds = tuple(f * r0.cost for f in factors)
        results[compiled] = plan(fm.grid, s, g, planner, heatmap=heat, config=config, stop=stop,
                                 seed=7, reference_length=ref, milestones=bounds)  # fmt: skip
    a, b = results[True], results[False]
    for field in ("success", "stop_reason", "cost", "iterations", "tree_size", "collision_checks",
                  "first_cost", "first_iteration"):  # fmt: skip
        assert getattr(a, field) == getattr(b, field), field
    np.testing.assert_array_equal(a.path, b.path)
    np.testing.assert_array_equal(a.trace_costs, b.trace_costs)
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
