"""A run's whole timed loop in one compiled call (64-bit Linux, :data:`.clock.IN_KERNEL`).

:func:`drive` does what :func:`vnrrt.planners.run.drive_python` does between compiled chunks
of :func:`vnrrt.planners.core.grow`, in the same order and with the same chunk sizes, so the
tree, its iterations and its costs are the same: record the time and iteration at which each
stop bound was first passed, stop when the stop bound is met or a budget is spent, else grow
another chunk (first :data:`FIRST_CHUNK` iterations, doubling up to :data:`MAX_CHUNK`; a chunk
ends early at the gap sampler's start, when its cells are found). It
returns to Python only when the run is over or the tree's arrays are full (the caller
enlarges them and calls again). Times are seconds on ``time.perf_counter``'s clock
(:func:`vnrrt.planners.clock.monotonic`) since ``t0``. Without the return to Python after
each chunk and each bound passed, a run that ends in a few hundred iterations costs one
dispatch instead of several (about 5 us each), and its times are taken when the bound is
passed, not after Python has taken over.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from vnrrt.planners.clock import monotonic
from vnrrt.planners.core import (
    RUNNING,
    TREE_FULL,
    Draws,
    Params,
    gaps_due,
    grow,
    plant,
    with_gaps,
)
from vnrrt.planners.tree import Counters, Scratch, Trace, Tree, finish

FIRST_CHUNK, MAX_CHUNK = 64, 4096  # iterations per chunk; budgets checked between
SOLVED, MAX_ITERATIONS, MAX_SECONDS = 3, 4, 5  # return codes of :func:`drive` (or TREE_FULL)


@njit(cache=True)
def drive(occ, tree, scratch, counters, trace, rng, draws, stops, p, first, budget, state, times,
          iters):  # fmt: skip
    """Plant the tree (when ``state[2]`` is 1) and grow it until the run is over.

    ``stops`` (M,) decreasing cost bounds; ``p`` the run's :class:`Params` (``first``: those
    of planting); ``budget`` ``(target, max_iterations, max_seconds, t0)`` (target ``inf``:
    the first solution; ``t0``: the run's start on the clock, seconds); ``state`` (3,) int64
    kept across calls: next chunk size, bounds passed, plant first; ``times`` (M,) float64
    and ``iters`` (M,) int64: when each bound was first passed (NaN / -1: never). Returns
    :data:`SOLVED`, :data:`MAX_ITERATIONS`, :data:`MAX_SECONDS` or
    :data:`~vnrrt.planners.core.TREE_FULL`.
    """
    target, max_iterations, max_seconds, t0 = budget
    if state[2]:
        plant(occ, tree, counters, scratch.stack, trace, first, stops)
        state[2] = 0
    status = RUNNING
    while True:
        now = monotonic() - t0
        for b in range(state[1], counters.milestone[0]):
            times[b], iters[b] = now, counters.iters[0]
        state[1] = counters.milestone[0]
        g = counters.goal[0]
        if g >= 0 and tree.cost[g] <= target:
            return SOLVED
        if status == TREE_FULL:
            return TREE_FULL
        if counters.iters[0] >= max_iterations:
            return MAX_ITERATIONS
        if now >= max_seconds:
            return MAX_SECONDS
        if gaps_due(draws, counters.iters[0]) <= 0:
            draws = with_gaps(occ, draws)
        n = min(state[0], max_iterations - counters.iters[0], gaps_due(draws, counters.iters[0]))
        status = grow(occ, tree, scratch, counters, trace, rng, draws, stops, p, n)
        state[0] = min(2 * state[0], MAX_CHUNK)


@njit(cache=True)
def drive_flat(occ, tree, scratch, counters, trace, rng, draws, stops, p, first, budget, state,
               times, iters):  # fmt: skip
    """:func:`drive` on plain tuples in place of the named ones (as
    :func:`vnrrt.planners.core.grow_flat`)."""
    return drive(occ, Tree(*tree), Scratch(*scratch), Counters(*counters), Trace(*trace), rng,
                 Draws(*draws), stops, Params(*p), Params(*first), budget, state, times,
                 iters)  # fmt: skip


@njit(cache=True)
def run_flat(occ, tree, scratch, counters, trace, rng, draws, stops, p, first, budget, state,
             times, iters):  # fmt: skip
    """:func:`drive_flat`, then, when the run is over, its result's arrays made in the same
    compiled call (:func:`vnrrt.planners.tree.finish`: path, segment lengths, trace
    iterations and costs): ``(code, path, segs, trace_iters, trace_costs)``, the arrays empty
    when the code is :data:`~vnrrt.planners.core.TREE_FULL` (the caller then enlarges the
    tree and calls again)."""
    code = drive_flat(occ, tree, scratch, counters, trace, rng, draws, stops, p, first, budget,
                      state, times, iters)  # fmt: skip
    if code == TREE_FULL:
        return code, np.zeros((0, 2)), np.zeros(0), np.zeros(0, np.int64), np.zeros(0)
    t, c, tr = Tree(*tree), Counters(*counters), Trace(*trace)
    path, segs, trace_iters, trace_costs = finish(t.links, t.pts, t.cost, c.goal[0], tr.iters,
                                                  tr.costs, c.trace_len[0], c.iters[0])  # fmt: skip
    return code, path, segs, trace_iters, trace_costs
