"""One planner run on validated inputs: the timed region of :meth:`vnrrt.planners.Planner.solve`.

The clock starts before the straight start-goal segment is tested (when ``straight_first``) and
stops when the stop rule or a budget is met and a grown tree's path and trace are taken out of
it (:func:`finished`, in the same compiled call: as OMPL's ``solve()`` builds its solution
path). The tree's arrays are allocated (or emptied for reuse) before it starts, as OMPL's
``setup()`` is outside its ``solve()`` times; growing them is inside. A free straight segment
that meets the stop rule is the exact optimum, known after that one segment test: its result
(a two-node tree) is written after the clock has stopped, as every result object is
(:func:`free_answer`; :mod:`.native` makes the same answer in one C call). Otherwise the tree
grows in compiled chunks of :func:`vnrrt.planners.core.grow`, budgets checked between chunks:
all in one compiled call on 64-bit Linux (:func:`drive_compiled`, :mod:`.loop`), else
returning to Python after each chunk (:func:`drive_python`); both grow the same tree. A
one-shot :func:`vnrrt.planners.plan` takes its tree's arrays from :data:`POOL`."""

from __future__ import annotations

import math
import threading
import time
from typing import NamedTuple

import numpy as np

from vnrrt.planners import clock, core, loop
from vnrrt.planners import tree as nodes
from vnrrt.planners.loop import FIRST_CHUNK, MAX_CHUNK
from vnrrt.planners.result import Milestone, PlanResult, made

FIRST_CAPACITY = 4096  # tree nodes allocated first; doubled when full (up to the budget)


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


class Budget(NamedTuple):
    """A run's budgets and trace size (:class:`vnrrt.planners.PlannerConfig`)."""

    max_iterations: int
    max_seconds: float
    trace_capacity: int


class Tree:
    """The state of one growing run: tree, scratch buffers, counters and trace (:mod:`.core`)."""

    def __init__(self, capacity: int, shape: tuple[int, int], bucket: float, trace: int):
        self.tree = nodes.new_tree(capacity, shape, bucket)
        self.scratch = nodes.new_scratch(capacity)
        self.counters = nodes.new_counters()
        self.trace = nodes.Trace(np.empty(trace, np.int64), np.empty(trace))
        self._flatten()

    def _flatten(self) -> None:
        """The arrays as plain tuples, as :func:`vnrrt.planners.core.grow_flat` takes them."""
        self.flat = tuple(self.tree), tuple(self.scratch), tuple(self.counters), tuple(self.trace)

    def enlarge(self, capacity: int) -> None:
        """Room for ``capacity`` nodes, the tree kept."""
        self.tree = nodes.enlarge(self.tree, capacity)
        self.scratch = nodes.new_scratch(capacity)
        self._flatten()

    @property
    def capacity(self) -> int:
        return len(self.tree.cost)

    def solved(self, target: float | None) -> bool:
        """Whether the goal is in the tree at a cost meeting ``target`` (None: any cost)."""
        g = int(self.counters.goal[0])
        return g >= 0 and (target is None or self.tree.cost[g] <= target)

    def reset(self) -> None:
        """Empty the tree, its arrays kept (a node's fields are written when it is added)."""
        for count in self.counters:
            count[0] = 0
        self.counters.goal[0] = -1
        self.tree.head.fill(-1)


class Workspace:
    """The arrays of the runs of one :class:`vnrrt.planners.Planner` on one map: allocated by
    the first run (``FIRST_CAPACITY`` nodes, grown as needed), emptied and reused by the next
    ones. One run at a time. A one-shot workspace (``pooled``, what :func:`vnrrt.planners.plan`
    uses) takes its first tree from :data:`POOL` and gives it back by :meth:`release`."""

    def __init__(self, shape: tuple[int, int], bucket: float, budget: Budget, pooled=False):
        self.shape, self.bucket, self.budget = shape, bucket, budget
        self.pooled = pooled
        self._tree: Tree | None = None

    @property
    def _key(self) -> tuple:
        capacity = min(self.budget.max_iterations + 2, FIRST_CAPACITY)
        return capacity, tuple(self.shape), self.bucket, self.budget.trace_capacity

    def fresh(self) -> Tree:
        """An empty tree (newly allocated, or taken from the pool, the first time)."""
        if self._tree is None:
            key = self._key
            self._tree = POOL.take(key) if self.pooled else None
            if self._tree is None:
                self._tree = Tree(key[0], self.shape, self.bucket, key[3])
        self._tree.reset()
        return self._tree

    def release(self) -> None:
        """Give the tree back to the pool (a pooled workspace of first size; no run may use
        it afterwards). A tree that grew is dropped, so the pool never holds a large one."""
        tree, self._tree, key = self._tree, None, self._key
        if self.pooled and tree is not None and tree.capacity == key[0]:
            POOL.give(key, tree)


class TreePool:
    """Emptied trees of finished one-shot runs, for the next one on a map of the same shape
    and settings (the allocation and first touch of a tree's ~0.4 MB cost a one-shot call
    more than a short run): at most ``per_key`` trees for each of the ``keys`` most recent
    keys ``(capacity, shape, bucket, trace capacity)``. Thread-safe; results never share
    a tree's arrays (:func:`result` copies what it returns)."""

    def __init__(self, keys: int = 8, per_key: int = 2):
        self.keys, self.per_key = keys, per_key
        self._trees: dict[tuple, list[Tree]] = {}
        self._lock = threading.Lock()

    def take(self, key: tuple) -> Tree | None:
        with self._lock:
            trees = self._trees.get(key)
            return trees.pop() if trees else None

    def give(self, key: tuple, tree: Tree) -> None:
        with self._lock:
            trees = self._trees.pop(key, [])  # re-inserted: the most recent key last
            if len(trees) < self.per_key:
                trees.append(tree)
            self._trees[key] = trees
            while len(self._trees) > self.keys:
                del self._trees[next(iter(self._trees))]

    def clear(self) -> None:
        with self._lock:
            self._trees.clear()


POOL = TreePool()


def stop_bounds(query: Query) -> np.ndarray:
    """The cost bounds the core reports passing, decreasing: ``inf`` (any solution), the
    extra bounds and the stop bound."""
    target = query.target
    if not query.bounds:  # the common case, without the set and the sort
        return np.array((math.inf,) if target is None or target == math.inf else (math.inf, target))
    wanted = {math.inf, *query.bounds, *([] if target is None else [target])}
    return np.array(sorted(wanted, reverse=True))


def straight_test(occ: np.ndarray, sx: float, sy: float, gx: float, gy: float,
                  straight: bool) -> tuple[float, float]:  # fmt: skip
    """A query's compiled checks (:func:`vnrrt.planners.core.query_test`): the start-goal
    distance when ``straight`` and the segment between them is free, -1 when it is blocked
    or not tested, :data:`~vnrrt.planners.core.BAD_ENDPOINT` when start or goal touches an
    obstacle or the border; and, with ``straight``, the seconds the call took (the first
    part of a run's time; the endpoints' two point tests are in it), else 0."""
    t0 = time.perf_counter()
    d = core.query_test(occ, sx, sy, gx, gy, straight)
    return d, (time.perf_counter() - t0 if straight else 0.0)


def straight_meets(d: float, target: float | None) -> bool:
    """Whether a straight segment of length ``d`` (:func:`straight_test`'s: < 0 when blocked
    or not tested) answers a query with stop bound ``target`` (None: any length)."""
    return d >= 0 and (target is None or d <= target)


def straight_answer(planner: str, query: Query, tested: tuple[float, float]) -> PlanResult | None:
    """The run's result when the straight segment ``tested`` (:func:`straight_test`: its
    length, -1 when blocked, and the seconds taken) meets the query's stop rule, else None
    (a tree is needed)."""
    d, found = tested
    if straight_meets(d, query.target):
        return straight_result(planner, d, found, *query)
    return None


def free_answer(
    occ: np.ndarray,
    sx: float,
    sy: float,
    gx: float,
    gy: float,
    target: float | None,
    planner: str,
    reference_length: float | None,
    setup_time: float,
    fallback_uniform: bool,
) -> PlanResult | tuple[float, float]:
    """The answer of a query whose straight segment is tested first: :func:`straight_result`
    when the segment from ``(sx, sy)`` to ``(gx, gy)`` is free and meets ``target`` (None: any
    length), else :func:`straight_test`'s ``(d, seconds)``. The Python version of
    :mod:`vnrrt.planners.native`'s C one."""
    tested = straight_test(occ, sx, sy, gx, gy, True)
    d, found = tested
    if not straight_meets(d, target):
        return tested
    return straight_result(planner, d, found, (sx, sy), (gx, gy), target, (), False,
                           reference_length, setup_time, fallback_uniform)  # fmt: skip


def straight_result(
    planner: str,
    d: float,
    found: float,
    start: tuple[float, float],
    goal: tuple[float, float],
    target: float | None,
    bounds: tuple = (),
    keep_tree: bool = False,
    reference_length: float | None = None,
    setup_time: float = 0.0,
    fallback_uniform: bool = False,
) -> PlanResult:
    """The result of a run answered after ``found`` seconds by the free straight segment of
    length ``d`` from ``start`` to ``goal``, the other arguments those of its
    :class:`Query` (in its order): the tree is the root and the goal joined to it (one
    segment test). The cost is ``d``, equal to the polyline length of the path (both are
    libm's ``hypot``)."""
    path = np.array((start, goal))
    values = STRAIGHT.copy()  # the fields every straight answer shares, then its own
    values["planner"] = planner
    values["path"] = path
    values["cost"] = values["first_cost"] = d
    values["time_to_first"] = values["time_to_stop"] = found
    values["trace_iterations"] = ROOT_TRACE.copy()
    values["trace_costs"] = np.array((d,))
    values["reference_length"] = reference_length
    values["target_cost"] = target
    values["fallback_uniform"] = fallback_uniform
    values["setup_time"] = setup_time
    if bounds:
        values["milestones"] = tuple(Milestone(b, found, 0) if d <= b else Milestone(b)
                                     for b in bounds)  # fmt: skip
    if keep_tree:
        values["tree_points"] = path.copy()
        values["tree_parents"] = np.array((-1, 0), np.int64)
    return made(values)


STRAIGHT = {
    "planner": "",
    "success": True,
    "stop_reason": "solved",
    "path": None,
    "cost": 0.0,
    "iterations": 0,
    "tree_size": 2,
    "collision_checks": 1,
    "time_to_first": 0.0,
    "time_to_stop": 0.0,
    "first_cost": 0.0,
    "first_iteration": 0,
    "trace_iterations": None,
    "trace_costs": None,
    "reference_length": None,
    "target_cost": None,
    "milestones": (),
    "fallback_uniform": False,
    "setup_time": 0.0,
    "tree_points": None,
    "tree_parents": None,
}  # a straight answer's fields (:func:`straight_result` sets those that vary); a copy per result
ROOT_TRACE = np.zeros(1, np.int64)  # a straight answer's trace iterations (copied per result)


class Setup(NamedTuple):
    """What every tree run of one :class:`vnrrt.planners.Planner` shares, made once before
    its first run (as OMPL's ``setup()``): the tree's arrays (``work``), the core's settings
    (:class:`vnrrt.planners.core.Params`) as a plain tuple whose query fields ``sx, sy, gx,
    gy`` are placeholders (:func:`query_params` fills them), and the sampler as the core
    reads it (``draws``, and ``flat_draws``: the same as a plain tuple, what the compiled
    loop takes)."""

    work: Workspace
    params: tuple
    draws: core.Draws
    flat_draws: tuple


SX = core.Params._fields.index("sx")  # sx, sy, gx, gy follow in this order: the query's
GOAL_RADIUS = core.Params._fields.index("goal_radius")
assert core.Params._fields[SX : SX + 4] == ("sx", "sy", "gx", "gy")


def query_params(params: tuple, query: Query, straight: bool) -> tuple[tuple, tuple]:
    """The core's settings of a run (``params``: :attr:`Setup.params`) with the query's
    start and goal, and those of planting (``first``): the same, with any node joining the
    goal when the straight segment is known to be free (``straight``). Plain tuples in
    :class:`vnrrt.planners.core.Params`' order."""
    p = params[:SX] + query.start + query.goal + params[SX + 4 :]
    first = (*p[:GOAL_RADIUS], math.inf, *p[GOAL_RADIUS + 1 :]) if straight else p
    return p, first


def search(
    occ: np.ndarray,
    query: Query,
    *,
    planner: str,
    setup: Setup,
    rng: np.ndarray,
    straight: bool,
    spent: float = 0.0,
) -> PlanResult:
    """Grow a tree (in ``setup.work``) from the start until the stop rule or a budget is met;
    ``straight``: the start-goal segment is known to be free (the goal joins the root at
    once); ``spent``: seconds of the run before this call (the straight-segment test)."""
    stops = stop_bounds(query)
    run = setup.work.fresh()  # allocated (or emptied) before the clock starts, as OMPL's setup()
    params, first = query_params(setup.params, query, straight)
    drive = drive_compiled if clock.IN_KERNEL else drive_python
    t0 = time.perf_counter() - spent
    job = Job(setup, params, first, rng, stops, query.target, t0)
    reason, times, iters, finished = drive(run, occ, job)
    elapsed = time.perf_counter() - t0
    reached = dict(zip(stops.tolist(), zip(times.tolist(), iters.tolist()), strict=True))
    return result(run, planner, query, reason=reason, reached=reached, elapsed=elapsed,
                  finished=finished)  # fmt: skip


REASONS = {loop.SOLVED: "solved", loop.MAX_ITERATIONS: "max_iterations",
           loop.MAX_SECONDS: "max_seconds"}  # fmt: skip


class Job(NamedTuple):
    """What a run's loop reads besides the tree and the grid: the planner's :class:`Setup`
    (its sampler and budgets), the run's settings (``params``; ``first``: those of planting;
    plain tuples in :class:`vnrrt.planners.core.Params`' order), the rng state, the stop
    bounds (decreasing), the stop bound to meet (None: the first solution) and the run's
    start ``t0`` (``time.perf_counter`` seconds)."""

    setup: Setup
    params: tuple
    first: tuple
    rng: np.ndarray
    stops: np.ndarray
    target: float | None
    t0: float


def drive_compiled(
    run: Tree, occ: np.ndarray, job: Job
) -> tuple[str, np.ndarray, np.ndarray, tuple]:
    """:func:`drive_python` in one compiled call (:func:`vnrrt.planners.loop.run_flat`, the
    result's arrays made in it), back in Python only to enlarge a full tree; the same tree,
    iterations, costs and arrays."""
    (times, iters), budget = unreached(len(job.stops)), job.setup.work.budget
    state = np.array([FIRST_CHUNK, 0, 1], np.int64)  # chunk, bounds passed, plant
    target = math.inf if job.target is None else float(job.target)
    limits = (target, int(budget.max_iterations), float(budget.max_seconds), job.t0)
    rest = (job.setup.flat_draws, job.stops, job.params, job.first, limits, state, times, iters)
    while True:  # after a full tree, the gap cells found in the call are found again (same)
        out = loop.run_flat(occ, *run.flat, job.rng, *rest)
        if out[0] != core.TREE_FULL:
            return REASONS[out[0]], times, iters, out[1:]
        make_room(run, budget)


def unreached(m: int) -> tuple[np.ndarray, np.ndarray]:
    """The times (s, float64, NaN) and iterations (int64, -1) at which ``m`` stop bounds
    were first passed, before a run."""
    times, iters = np.empty(m), np.empty(m, np.int64)
    times.fill(math.nan)
    iters.fill(-1)
    return times, iters


def make_room(run: Tree, budget: Budget) -> None:
    """Double a full tree's room, up to the budget's (root, goal and a node per iteration)."""
    if run.capacity >= budget.max_iterations + 2:
        raise RuntimeError(f"tree of {run.capacity} nodes full before the budget")
    run.enlarge(min(2 * run.capacity, budget.max_iterations + 2))


def drive_python(run: Tree, occ: np.ndarray, job: Job) -> tuple[str, np.ndarray, np.ndarray, tuple]:
    """Plant the tree and grow it in compiled chunks until the stop rule or a budget is met,
    timing it in Python (where :data:`vnrrt.planners.clock.IN_KERNEL` is False).

    Returns ``(stop_reason, times, iterations, finished)``: per entry of ``stops``
    (decreasing cost bounds), the time (s since ``t0``, ``time.perf_counter``) and iteration
    at which it was first reached (NaN / -1: never), float64 and int64 as
    :func:`drive_compiled` returns them; ``finished``: the result's arrays
    (:func:`finished`)."""
    reason, times, iters = grow_python(run, occ, job)
    return reason, times, iters, finished(run)


def finished(run: Tree) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """A finished run's path, segment lengths, trace iterations and costs
    (:func:`vnrrt.planners.tree.finish`)."""
    c, tree, trace = run.counters, run.tree, run.trace
    return nodes.finish(tree.links, tree.pts, tree.cost, int(c.goal[0]), trace.iters,
                        trace.costs, int(c.trace_len[0]), int(c.iters[0]))  # fmt: skip


def grow_python(run: Tree, occ: np.ndarray, job: Job) -> tuple[str, np.ndarray, np.ndarray]:
    """:func:`drive_python`'s loop: its first three returns."""
    tree, _, c, trace = run.flat
    stops, budget = job.stops, job.setup.work.budget
    core.plant_flat(occ, tree, c, run.scratch.stack, trace, job.first, stops)
    c = run.counters
    times, iters = unreached(len(stops))
    chunk, passed, status = FIRST_CHUNK, 0, core.RUNNING
    draws, params_t = job.setup.draws, job.params
    draws_t = job.setup.flat_draws
    while True:
        now = time.perf_counter() - job.t0
        for m in range(passed, int(c.milestone[0])):
            times[m], iters[m] = now, int(c.iters[0])
        passed = int(c.milestone[0])
        if run.solved(job.target):
            return "solved", times, iters
        if status == core.TREE_FULL:
            make_room(run, budget)
        if c.iters[0] >= budget.max_iterations:
            return "max_iterations", times, iters
        if now >= budget.max_seconds:
            return "max_seconds", times, iters
        if core.gaps_due(draws, int(c.iters[0])) <= 0:
            draws = core.with_gaps(occ, draws)
            draws_t = tuple(draws)
        due = core.gaps_due(draws, int(c.iters[0]))
        n = min(chunk, budget.max_iterations - int(c.iters[0]), due)
        status = core.grow_flat(occ, *run.flat, job.rng, draws_t, stops, params_t, n)
        chunk = min(2 * chunk, MAX_CHUNK)


def result(
    run: Tree,
    planner: str,
    query: Query,
    *,
    reason: str,
    reached: dict[float, tuple[float, int]],
    elapsed: float,
    finished: tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray],
) -> PlanResult:
    """The :class:`PlanResult` of a finished run; ``reached[bound] = (seconds, iteration)``;
    ``finished``: its path, segment lengths, trace iterations and costs (:func:`finished`)."""
    c, tree = run.counters, run.tree
    n, g, k = int(c.nodes[0]), int(c.goal[0]), int(c.trace_len[0])
    path, segs, trace_it, trace_cost = finished
    first_time, first_iter = reached[math.inf]
    return made({
        "planner": planner,
        "success": reason == "solved",
        "stop_reason": reason,
        "path": path,
        "cost": float(np.add.reduce(segs)) if g >= 0 else math.inf,  # = polyline_length(path)
        "iterations": int(c.iters[0]),
        "tree_size": n,
        "collision_checks": int(c.checks[0]),
        "time_to_first": first_time,
        "time_to_stop": elapsed,
        "first_cost": float(trace_cost[0]) if k else math.inf,
        "first_iteration": first_iter,
        "trace_iterations": trace_it,
        "trace_costs": trace_cost,
        "reference_length": query.reference_length,
        "target_cost": query.target,
        "milestones": tuple(Milestone(b, *reached[b]) for b in query.bounds),
        "fallback_uniform": query.fallback_uniform,
        "setup_time": query.setup_time,
        "tree_points": tree.pts[:n].copy() if query.keep_tree else None,
        "tree_parents": tree.links[:n, nodes.PARENT].copy() if query.keep_tree else None,
    })  # fmt: skip
