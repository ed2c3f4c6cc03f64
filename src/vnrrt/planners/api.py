"""Public entry point :func:`plan`: validate inputs, build the sampler, run the core, time it.

Coordinates follow :mod:`vnrrt.grid`: ``grid`` is ``(H, W)`` indexed ``grid[y, x]``
(nonzero = obstacle), start and goal are continuous ``(x, y)`` pixel points (cell
centres ``(x + 0.5, y + 0.5)`` for dataset instances). Timings cover the tree
search only: building the sampler from a heatmap (per map, once; reported as
``setup_time``), JIT compilation (once per process, :func:`warmup`) and the reference-length
computation (an oracle, not part of planning) are outside the timed region. With
``straight_first``, a free start-goal segment that meets the stop rule is the answer: the run's
time is that one segment test. A sampler can be built once with :func:`make_sampler` and
passed to many :func:`plan` calls.
"""

from __future__ import annotations

import dataclasses
import functools
import logging
import math
import time

import numpy as np

from vnrrt.grid import GridError, as_occupancy, as_point
from vnrrt.planners import core
from vnrrt.planners.collision import point_free, polyline_length, segment_free
from vnrrt.planners.config import PLANNERS, PlannerConfig
from vnrrt.planners.reference import reference_length as compute_reference
from vnrrt.planners.result import Milestone, PlanResult
from vnrrt.planners.samplers import Sampler, heatmap_sampler, rng_state, uniform_sampler

log = logging.getLogger(__name__)

FIRST_CHUNK, MAX_CHUNK = 64, 4096  # iterations per compiled call; budgets checked between
FIRST_CAPACITY = 4096  # tree nodes allocated first; doubled when full (up to the budget)


def make_sampler(
    planner: str, shape: tuple[int, int], heatmap=None, tau=None, mix: float = 0.5
) -> Sampler:
    """The sampler of ``planner`` for an ``(H, W)`` map (see :mod:`.samplers`)."""
    if planner not in PLANNERS:
        raise ValueError(f"unknown planner {planner!r}; choose from {PLANNERS}")
    if planner == "rrt_star":
        if heatmap is not None:
            raise ValueError("rrt_star samples uniformly and takes no heatmap")
        return uniform_sampler(shape)
    if heatmap is None:
        raise ValueError(f"{planner} needs a heatmap of shape {tuple(shape)}")
    if planner == "m_vnrrt_star":
        if tau is None or not math.isfinite(tau):
            raise ValueError(f"m_vnrrt_star needs a finite mask threshold tau, got {tau!r}")
        return heatmap_sampler(heatmap, shape, mix, float(tau))
    if tau is not None:
        raise ValueError(f"{planner} takes no tau (only m_vnrrt_star masks its heatmap)")
    return heatmap_sampler(heatmap, shape, mix)


SAMPLER_KINDS = {
    "rrt_star": "uniform",
    "nrrt_star": "heatmap",
    "vnrrt_star": "heatmap",
    "m_vnrrt_star": "masked",
}


def check_sampler(
    sampler: Sampler, planner: str, shape: tuple[int, int], heatmap=None, tau=None
) -> None:
    """Raise ``ValueError`` unless ``sampler`` is what ``planner`` samples from on a map of
    ``shape`` (a prebuilt sampler replaces ``heatmap`` and ``tau``)."""
    if planner not in PLANNERS:
        raise ValueError(f"unknown planner {planner!r}; choose from {PLANNERS}")
    if heatmap is not None or tau is not None:
        raise ValueError("give either a prebuilt sampler or heatmap/tau, not both")
    if sampler.kind != SAMPLER_KINDS[planner]:
        raise ValueError(
            f"{planner} samples from a {SAMPLER_KINDS[planner]} sampler, got a {sampler.kind} one"
        )
    if tuple(sampler.shape) != tuple(shape):
        raise GridError(f"sampler is for shape {sampler.shape}, the grid has shape {shape}")


def _check_endpoint(occ: np.ndarray, point, name: str) -> tuple[float, float]:
    x, y = as_point(occ, point, name)
    if not point_free(occ, (x, y)):
        raise GridError(f"{name} {(x, y)} touches an obstacle cell or the map border")
    return x, y


def _params(cfg: PlannerConfig, occ: np.ndarray, start, goal) -> core.Params:
    """The core's settings of a run (:class:`vnrrt.planners.core.Params`)."""
    gamma = cfg.gamma
    if gamma is None:  # RRT* bound 2 (1 + 1/d)^(1/d) (free area / unit-ball area)^(1/d), d=2
        gamma = 2.0 * math.sqrt(1.5) * math.sqrt(np.count_nonzero(occ == 0) / math.pi)
    return core.Params(
        eta=float(cfg.eta),
        gamma=float(gamma) * cfg.gamma_factor if cfg.radius_mode == "shrinking" else 0.0,
        radius=float(cfg.fixed_radius),
        goal_radius=float(cfg.eta if cfg.goal_radius is None else cfg.goal_radius),
        sx=float(start[0]),
        sy=float(start[1]),
        gx=float(goal[0]),
        gy=float(goal[1]),
        min_spacing=float(cfg.min_spacing),
        bucket=max(min(cfg.eta, max(occ.shape)) / 2, 1.0),  # an unlimited step: the map
        informed=bool(cfg.informed),
    )


def plan(
    grid: np.ndarray,
    start,
    goal,
    planner: str = "rrt_star",
    heatmap: np.ndarray | None = None,
    tau: float | None = None,
    stop: str = "initial",
    reference_length: float | None = None,
    seed=0,
    config: PlannerConfig | None = None,
    milestones: tuple[float, ...] = (),
    keep_tree: bool = False,
    sampler: Sampler | None = None,
    **overrides,
) -> PlanResult:
    """Plan from ``start`` to ``goal`` with one of the paper's RRT* variants.

    Args:
        grid: ``(H, W)`` bool/int occupancy, nonzero = obstacle, indexed ``grid[y, x]``.
        start, goal: continuous points ``(x, y)`` in pixels, in free cells and not touching
            an obstacle or the map border.
        planner: ``'rrt_star'`` (uniform), ``'nrrt_star'`` / ``'vnrrt_star'`` (heatmap
            sampler, Algorithm 2) or ``'m_vnrrt_star'`` (heatmap masked below ``tau``).
        heatmap: ``(H, W)`` non-negative sampling weights, needed by all but RRT*.
        tau: mask threshold for M-VNRRT* (defaults to ``config.tau``).
        stop: ``'initial'`` (first solution) or ``'optimal'`` (cost <= (1 + eps) x ref).
        reference_length: reference for ``'optimal'``; None computes ``config.reference``
            (A* length by default) between the cells containing start and goal.
        seed: int or tuple of ints seeding the sampler (same seed, same result).
        config: settings (default :class:`PlannerConfig`); ``overrides`` replace fields,
            e.g. ``eta=5.0, max_seconds=2``.
        milestones: extra cost bounds (pixels) whose first-reach time is recorded.
        keep_tree: also return the tree (points and parents) for drawing.
        sampler: a sampler already built by :func:`make_sampler` for this planner and map
            (then ``heatmap`` and ``tau`` are not given); saves rebuilding it per run.

    Returns:
        A :class:`PlanResult`; hitting an iteration or time budget gives ``success=False``.

    Raises:
        GridError: malformed grid, bad start/goal, heatmap of the wrong shape or values.
        NoPathError: the A* reference is needed and start and goal are not connected.
        ValueError: unknown planner or stop rule, bad settings.
    """
    cfg = (config or PlannerConfig()).replace(**overrides)
    occ = as_occupancy(grid)
    start = _check_endpoint(occ, start, "start")
    goal = _check_endpoint(occ, goal, "goal")
    if stop not in ("initial", "optimal"):
        raise ValueError(f"unknown stop rule {stop!r}; use 'initial' or 'optimal'")
    if planner == "m_vnrrt_star" and tau is None and sampler is None:
        tau = cfg.tau
    t0 = time.perf_counter()
    if sampler is None:
        sampler = make_sampler(planner, occ.shape, heatmap, tau, cfg.mix)
    else:
        check_sampler(sampler, planner, occ.shape, heatmap, tau)
    setup = time.perf_counter() - t0
    if reference_length is None and stop == "optimal":
        reference_length = compute_reference(occ, start, goal, cfg.reference)
    if reference_length is not None and not (
        math.isfinite(reference_length) and reference_length >= 0
    ):
        raise ValueError(f"reference_length must be finite and >= 0, got {reference_length}")
    target = None if stop == "initial" else (1.0 + cfg.eps) * reference_length
    warmup()
    result = _timed(occ, start, goal, planner, sampler, target, milestones, seed, cfg, keep_tree)
    result = dataclasses.replace(result, reference_length=reference_length, setup_time=setup)
    if log.isEnabledFor(logging.DEBUG):
        log.debug("%s", result.summary())
    return result


class _Run:
    """The state of one run: tree, scratch buffers, counters and trace (:mod:`.core`)."""

    def __init__(self, capacity: int, shape: tuple[int, int], bucket: float, trace: int):
        self.tree = core.new_tree(capacity, shape, bucket)
        self.scratch = core.new_scratch(capacity)
        self.counters = core.new_counters()
        self.trace = core.Trace(np.empty(trace, np.int64), np.empty(trace))

    def enlarge(self, capacity: int) -> None:
        """Room for ``capacity`` nodes, the tree kept."""
        self.tree = core.enlarge(self.tree, capacity)
        self.scratch = core.new_scratch(capacity)

    @property
    def capacity(self) -> int:
        return len(self.tree.cost)


def _timed(occ, start, goal, planner, sampler, target, milestones, seed, cfg, keep_tree):
    """Plan on validated inputs; ``target`` None = first solution. The seed's generator, the
    core's settings and the stop bounds are set up first; the timed region is the run."""
    bounds = tuple(float(m) for m in milestones)
    wanted = {math.inf, *bounds, *([] if target is None else [target])}
    stops = np.array(sorted(wanted, reverse=True))
    rng = rng_state(seed)
    p = _params(cfg, occ, start, goal)
    cdf = sampler.cdf if sampler.cdf.size else np.zeros(1)
    draws = core.Draws(float(sampler.mix), cdf, max(sampler.last, 0))
    t0 = time.perf_counter()
    straight = cfg.straight_first and segment_free(occ, p.sx, p.sy, p.gx, p.gy)
    found = time.perf_counter() - t0
    answered = straight and (target is None or math.dist(start, goal) <= target)
    capacity = 2 if answered else min(cfg.max_iterations + 2, FIRST_CAPACITY)  # root and goal
    run = _Run(capacity, occ.shape, p.bucket, cfg.trace_capacity)
    _start(run, occ, p, stops, straight)
    if answered and _solved(run, target):  # known after one segment test (see _solved_clock)
        clock = _solved_clock(found)
    else:
        clock = functools.partial(_since, t0)
    reason, times, iters = _drive(run, occ, draws, p, rng, stops, target, cfg, clock)
    elapsed = clock()
    reached = {b: (float(t), int(i)) for b, t, i in zip(stops, times, iters, strict=True)}
    result = _result(run, planner, reason, reached, elapsed, keep_tree)
    extra = tuple(Milestone(b, *reached[b]) for b in bounds)
    return dataclasses.replace(
        result, target_cost=target, milestones=extra, fallback_uniform=sampler.fallback_uniform
    )


def _since(t0: float) -> float:
    """Seconds since ``t0`` (``time.perf_counter``): the clock of a run."""
    return time.perf_counter() - t0


def _solved_clock(found: float):
    """The clock of a run answered by the straight segment: a free start-goal segment that
    meets the stop rule is the exact optimum, known after the one segment test at ``found``
    seconds; the two-node tree that records it is bookkeeping, built (like the result) after
    the clock has stopped, so the time stays proportional to the work done."""
    return lambda: found


def _solved(run: _Run, target: float | None) -> bool:
    """Whether the goal is in the tree at a cost meeting the stop bound (None: any cost)."""
    g = int(run.counters.goal[0])
    return g >= 0 and (target is None or run.tree.cost[g] <= target)


def _start(run: _Run, occ, p: core.Params, stops, straight: bool) -> None:
    """The root at the start; the goal joins it when it is within reach and visible, or at
    any distance when the straight segment is known to be free (``straight``: the optimum)."""
    first = p._replace(goal_radius=math.inf) if straight else p
    core.plant(occ, run.tree, run.counters, run.scratch.stack, run.trace, first, stops)


def _drive(run, occ, draws, p, rng, stops, target, cfg, clock):
    """Grow the planted tree (:func:`_start`) in compiled chunks until the stop rule or a
    budget is met.

    Returns ``(stop_reason, times, iterations)``: per entry of ``stops`` (decreasing cost
    bounds), the time (``clock()``, s since the run's start) and iteration at which it was
    first reached.
    """
    c = run.counters
    times, iters = np.full(len(stops), math.nan), np.full(len(stops), -1, np.int64)
    chunk, passed, status = FIRST_CHUNK, 0, core.RUNNING
    while True:
        now = clock()
        times[passed : c.milestone[0]] = now
        iters[passed : c.milestone[0]] = c.iters[0]
        passed = c.milestone[0]
        if _solved(run, target):
            return "solved", times, iters
        if status == core.TREE_FULL:
            if run.capacity >= cfg.max_iterations + 2:  # root, goal and a node per iteration
                raise RuntimeError(f"tree of {run.capacity} nodes full before the budget")
            run.enlarge(min(2 * run.capacity, cfg.max_iterations + 2))
        if c.iters[0] >= cfg.max_iterations:
            return "max_iterations", times, iters
        if now >= cfg.max_seconds:
            return "max_seconds", times, iters
        n = min(chunk, cfg.max_iterations - int(c.iters[0]))
        status = core.grow(occ, run.tree, run.scratch, c, run.trace, rng, draws, stops, p, n)
        chunk = min(2 * chunk, MAX_CHUNK)


def _result(run: _Run, planner, reason, reached, elapsed, keep_tree) -> PlanResult:
    """Assemble a :class:`PlanResult` from a finished run (stop-rule fields left empty)."""
    c, tree = run.counters, run.tree
    n, g, k = int(c.nodes[0]), int(c.goal[0]), int(c.trace_len[0])
    path = core.branch(tree.links, tree.pts, g) if g >= 0 else np.zeros((0, 2))
    cost = polyline_length(path) if g >= 0 else math.inf
    trace_it, trace_cost = run.trace.iters[:k].copy(), run.trace.costs[:k].copy()
    if k and trace_cost[-1] != tree.cost[g]:
        trace_it = np.append(trace_it, c.iters[0])
        trace_cost = np.append(trace_cost, tree.cost[g])
    first_time, first_iter = reached[math.inf]
    return PlanResult(
        planner=planner,
        success=reason == "solved",
        stop_reason=reason,
        path=path,
        cost=cost,
        iterations=int(c.iters[0]),
        tree_size=n,
        collision_checks=int(c.checks[0]),
        time_to_first=first_time,
        time_to_stop=elapsed,
        first_cost=float(trace_cost[0]) if k else math.inf,
        first_iteration=first_iter,
        trace_iterations=trace_it,
        trace_costs=trace_cost,
        tree_points=tree.pts[:n].copy() if keep_tree else None,
        tree_parents=tree.links[:n, core.PARENT].copy() if keep_tree else None,
    )


@functools.cache
def warmup() -> None:
    """Compile (or load from numba's disk cache) every kernel once per process, so that
    reported timings exclude JIT compilation."""
    occ = np.zeros((8, 8), np.uint8)
    occ[2:6, 4] = 1
    cfg = PlannerConfig(max_iterations=200)
    heat = np.ones((8, 8))
    for planner, hm in (("rrt_star", None), ("vnrrt_star", heat)):
        sampler = make_sampler(planner, occ.shape, hm)
        for informed in (False, True):
            c = cfg.replace(informed=informed)
            _timed(occ, (1.5, 3.5), (6.5, 3.5), planner, sampler, 0.0, (), 0, c, False)
    log.debug("planner kernels compiled")
