"""One timed planner run on a checked query: the settings and arrays runs share
(:class:`Setup`), the compiled loop that grows the tree (:func:`grow_tree`) and the
:class:`PlanResult` built from it. ``occ`` is the ``(H, W)`` uint8 grid indexed ``occ[y, x]``
(nonzero = obstacle), points ``(x, y)`` pixels, times seconds on ``time.perf_counter``'s clock.

The clock starts before the straight start-goal segment is tested (``straight_first``: a free
segment that meets the stop rule is the exact optimum and ends the run) and stops when the
stop rule or a budget is met and the path and trace are out of the tree (as OMPL's
``solve()``). The tree grows in chunks of :func:`vnrrt.planners.rrt_star.grow`
(:data:`FIRST_CHUNK` iterations, doubling up to :data:`MAX_CHUNK`), the budgets checked and
the bounds' first-pass times taken between chunks, in one compiled call that returns when
the run is over or the tree is full (enlarged inside the clock). The arrays are allocated or
emptied before the clock starts, as OMPL's ``setup()`` is outside its ``solve()`` times.
"""

from __future__ import annotations

import functools
import math
import time
from typing import NamedTuple

import numpy as np
from numba import njit

from vnrrt.planners import rrt_star
from vnrrt.planners import tree as nodes
from vnrrt.planners.clock import monotonic
from vnrrt.planners.config import PlannerConfig
from vnrrt.planners.result import Milestone, PlanResult
from vnrrt.planners.rrt_star import TREE_FULL, Params
from vnrrt.planners.samplers import Draws, Sampler, rng_state

FIRST_CAPACITY = 4096  # tree nodes allocated first; doubled when full (up to the budget)
FIRST_CHUNK, MAX_CHUNK = 64, 4096  # iterations per chunk; budgets checked between
SOLVED, MAX_ITERATIONS, MAX_SECONDS = 3, 4, 5  # return codes of :func:`grow_tree` (or TREE_FULL)
REASONS = {SOLVED: "solved", MAX_ITERATIONS: "max_iterations", MAX_SECONDS: "max_seconds"}


class Query(NamedTuple):
    """What one run is asked (lengths in pixels): start and goal ``(x, y)``, the stop bound
    ``target`` (None: the first solution), the extra cost ``bounds`` whose first-reach is
    recorded, whether the tree is returned, and the fields copied into the result."""

    start: tuple[float, float]
    goal: tuple[float, float]
    target: float | None
    bounds: tuple[float, ...]
    keep_tree: bool
    reference_length: float | None
    setup_time: float
    fallback_uniform: bool


class Setup:
    """What every run of one planner on one map shares (as OMPL's ``setup()``): the budgets
    (made first: a straight answer needs only them), then, each when a run first needs it,
    the core's settings, the sampler as the core reads it and the tree's arrays (one run at
    a time)."""

    def __init__(self, occ: np.ndarray, cfg: PlannerConfig, sampler: Sampler):
        self.occ, self.cfg, self.sampler = occ, cfg, sampler
        self._tree: nodes.Arrays | None = None
        free = occ.size - np.count_nonzero(occ) if cfg.scales_budgets else 0
        self.budget = cfg.budgets(free)  # (max_iterations, max_seconds) on this map

    @functools.cached_property
    def bucket(self) -> float:
        """The bucket grid's side (pixels): half the steer step (an unlimited step: the
        map's), at least a pixel."""
        return max(min(self.cfg.eta, max(self.occ.shape)) / 2, 1.0)

    @functools.cached_property
    def params(self) -> Params:
        """The core's settings (the config's and the map's gamma; start and goal 0)."""
        cfg = self.cfg
        return Params(
            eta=float(cfg.eta),
            gamma=gamma(self.occ, cfg) if cfg.radius_mode == "shrinking" else 0.0,
            radius=float(cfg.fixed_radius),
            goal_radius=float(cfg.eta if cfg.goal_radius is None else cfg.goal_radius),
            sx=0.0, sy=0.0, gx=0.0, gy=0.0,  # the query's: run()
            min_spacing=float(cfg.min_spacing),
            bucket=self.bucket,
            informed=bool(cfg.informed),
            refine=float(cfg.refine),
            pull_parents=bool(cfg.pull_parents),
            refine_branches=float(cfg.refine_branches),
        )  # fmt: skip

    @functools.cached_property
    def draws(self) -> tuple:
        """The sampler and the gap sampler as the core reads them (a plain :class:`Draws`)."""
        cfg = self.cfg
        draws = self.sampler.draws(
            gap_share=cfg.gap_share, gap_width=cfg.gap_width, gap_after=cfg.gap_after
        )
        return tuple(draws)

    def fresh(self) -> nodes.Arrays:
        """An empty tree: allocated (:data:`FIRST_CAPACITY` nodes, or the budget's) by the
        first run, emptied by the next ones."""
        if self._tree is None:
            capacity = min(self.budget[0] + 2, FIRST_CAPACITY)
            self._tree = nodes.Arrays(
                capacity, self.occ.shape, self.bucket, self.cfg.trace_capacity
            )
        self._tree.reset()
        return self._tree


def gamma(occ: np.ndarray, cfg: PlannerConfig) -> float:
    """The shrinking-radius constant: ``cfg.gamma_factor`` x (``cfg.gamma``, or the RRT*
    bound ``2 sqrt(1.5) sqrt(F / pi)`` of the map ``occ`` of F free cells)."""
    factor = float(cfg.gamma_factor)
    if cfg.gamma is not None:
        return factor * float(cfg.gamma)
    free = occ.size - np.count_nonzero(occ)
    return factor * 2.0 * math.sqrt(1.5) * math.sqrt(free / math.pi)


def run(occ: np.ndarray, query: Query, *, planner: str, setup: Setup, seed) -> PlanResult:
    """The timed run of ``query`` (module doc) with ``setup``'s settings and arrays, sampling
    from the xoshiro256** generator seeded by ``seed`` (:func:`.samplers.rng_state`)."""
    (sx, sy), (gx, gy) = query.start, query.goal
    target, d, spent, cfg = query.target, -1.0, 0.0, setup.cfg
    if cfg.straight_first:
        t0 = time.perf_counter()
        d = rrt_star.straight_cost(occ, sx, sy, gx, gy)  # -1: blocked
        spent = time.perf_counter() - t0
        if d >= 0 and (target is None or d <= target):
            return straight_result(planner, d, spent, query, setup.budget)
    stops, rng = stop_bounds(query), rng_state(seed)
    tree = setup.fresh()  # allocated (or emptied) before the clock starts, as OMPL's setup()
    params = setup.params._replace(sx=sx, sy=sy, gx=gx, gy=gy)
    first = params._replace(goal_radius=math.inf) if d >= 0 else params  # planting
    times, iters = np.full(len(stops), math.nan), np.full(len(stops), -1, np.int64)
    state = np.array([FIRST_CHUNK, 0, 1], np.int64)  # chunk, bounds passed, plant
    t0 = time.perf_counter() - spent
    max_iterations, max_seconds = setup.budget
    limits = (math.inf if target is None else float(target), int(max_iterations),
              float(max_seconds), t0)  # fmt: skip
    while True:  # after a full tree, the gap cells found in the call are found again (same)
        code, *arrays = grow_tree(occ, *tree.flat, rng, setup.draws, stops, tuple(params),
                                  tuple(first), limits, state, times, iters)  # fmt: skip
        if code != TREE_FULL:
            break
        tree.enlarge(max_iterations)
    elapsed = time.perf_counter() - t0
    reached = dict(zip(stops.tolist(), zip(times.tolist(), iters.tolist()), strict=True))
    c, t = tree.counters, tree.tree
    counts = (int(c.iters[0]), int(c.nodes[0]), int(c.checks[0]))
    cost = float(np.add.reduce(arrays[1])) if len(arrays[0]) else math.inf  # = polyline_length
    return result(planner, query, setup.budget, reason=REASONS[code], reached=reached,
                  elapsed=elapsed, counts=counts, cost=cost, arrays=arrays,
                  tree=(t.pts, t.links[:, nodes.PARENT]))  # fmt: skip


def stop_bounds(query: Query) -> np.ndarray:
    """The cost bounds the core reports passing, decreasing: ``inf`` (any solution), the
    extra bounds and the stop bound."""
    target = [] if query.target is None else [query.target]
    return np.array(sorted({math.inf, *query.bounds, *target}, reverse=True))


@njit(cache=True)
def grow_tree(occ, tree, scratch, counters, trace, rng, draws, stops, p, first, limits, state,
              times, iters):  # fmt: skip
    """Plant the tree (when ``state[2]`` is 1) and grow it until the run is over; returns
    ``(code, path, segs, trace_iters, trace_costs)`` (:func:`vnrrt.planners.tree.finish`;
    empty when ``code`` is :data:`~vnrrt.planners.rrt_star.TREE_FULL`: enlarge, call again).

    ``tree``, ``scratch``, ``counters``, ``trace`` (:attr:`.tree.Arrays.flat`), ``draws`` and
    ``p`` (``first``: those of planting) are plain tuples (:class:`Draws`, :class:`Params`);
    ``stops`` (M,) decreasing cost bounds; ``limits`` ``(target, max_iterations,
    max_seconds, t0)`` (target ``inf``: the first solution; ``t0``: the run's start on the
    clock, seconds); ``state`` (3,) int64 kept across calls: next chunk size, bounds passed,
    plant first; ``times`` (M,) float64 and ``iters`` (M,) int64: when each bound was first
    passed (NaN / -1: never).
    """
    t, c, tr = nodes.Tree(*tree), nodes.Counters(*counters), nodes.Trace(*trace)
    scratch, draws, p = nodes.Scratch(*scratch), Draws(*draws), Params(*p)
    target, max_iterations, max_seconds, t0 = limits
    if state[2]:
        rrt_star.plant(occ, t, c, scratch.stack, tr, Params(*first), stops)
        state[2] = 0
    status = rrt_star.RUNNING
    while True:
        now = monotonic() - t0
        for b in range(state[1], c.milestone[0]):
            times[b], iters[b] = now, c.iters[0]
        state[1] = c.milestone[0]
        code = rrt_star.RUNNING
        if c.goal[0] >= 0 and t.cost[c.goal[0]] <= target:
            code = SOLVED
        elif status == TREE_FULL:
            return TREE_FULL, np.zeros((0, 2)), np.zeros(0), np.zeros(0, np.int64), np.zeros(0)
        elif c.iters[0] >= max_iterations:
            code = MAX_ITERATIONS
        elif now >= max_seconds:
            code = MAX_SECONDS
        if code != rrt_star.RUNNING:
            path, segs, trace_iters, trace_costs = nodes.finish(
                t.links, t.pts, t.cost, c.goal[0], tr.iters, tr.costs, c.trace_len[0], c.iters[0]
            )
            return code, path, segs, trace_iters, trace_costs
        if rrt_star.gaps_due(draws, c.iters[0]) <= 0:
            draws = rrt_star.with_gaps(occ, draws)
        n = min(state[0], max_iterations - c.iters[0], rrt_star.gaps_due(draws, c.iters[0]))
        status = rrt_star.grow(occ, t, scratch, c, tr, rng, draws, stops, p, n)
        state[0] = min(2 * state[0], MAX_CHUNK)


def result(planner: str, query: Query, budget: tuple[int, float], *, reason: str,
           reached: dict[float, tuple[float, int]], elapsed: float, counts: tuple[int, int, int],
           cost: float, arrays, tree) -> PlanResult:  # fmt: skip
    """The :class:`PlanResult` of a finished run with ``budget`` ``(max_iterations,
    max_seconds)``: ``reached[bound] = (seconds, iteration)`` for ``inf`` and each of
    ``query.bounds``; ``counts`` its ``(iterations, tree nodes N, collision checks)``;
    ``cost`` its path's length (``inf``: none); ``arrays`` its path, segment lengths, trace
    iterations and costs (:func:`grow_tree`); ``tree`` the node positions ``(>= N, 2)`` and
    parents ``(>= N,)``, copied when kept."""
    iterations, n, checks = counts
    path, _, trace_iterations, trace_costs = arrays
    first_time, first_iteration = reached[math.inf]
    keep = query.keep_tree
    return PlanResult(
        planner=planner,
        success=reason == "solved",
        stop_reason=reason,
        path=path,
        cost=cost,
        iterations=iterations,
        tree_size=n,
        collision_checks=checks,
        time_to_first=first_time,
        time_to_stop=elapsed,
        first_cost=float(trace_costs[0]) if len(trace_costs) else math.inf,
        first_iteration=first_iteration,
        trace_iterations=trace_iterations,
        trace_costs=trace_costs,
        reference_length=query.reference_length,
        target_cost=query.target,
        milestones=tuple(Milestone(b, *reached[b]) for b in query.bounds),
        fallback_uniform=query.fallback_uniform,
        setup_time=query.setup_time,
        budget=budget,
        tree_points=tree[0][:n].copy() if keep else None,
        tree_parents=tree[1][:n].copy() if keep else None,
    )


def straight_result(planner: str, d: float, found: float, query: Query,
                    budget: tuple[int, float]) -> PlanResult:  # fmt: skip
    """The result of a run (with ``budget``) answered after ``found`` seconds by the free
    straight segment of length ``d`` from start to goal: the tree is the root and the goal
    joined to it (one segment test). The cost is ``d``, equal to the polyline length of the
    path (both are libm's ``hypot``)."""
    path, cost = np.array((query.start, query.goal)), np.array((d,))
    reached = {b: (found, 0) if d <= b else (math.nan, -1) for b in (math.inf, *query.bounds)}
    return result(planner, query, budget, reason="solved", reached=reached, elapsed=found,
                  counts=(0, 2, 1), cost=d, arrays=(path, cost, np.zeros(1, np.int64), cost),
                  tree=(path, np.array((-1, 0), np.int64)))  # fmt: skip
