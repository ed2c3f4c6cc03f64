"""The RRT* tree in preallocated arrays: nodes, parent/child links, costs, the bucket grid of
:mod:`.spatial`, and the sparse best-cost trace (compiled with numba).

Positions are continuous ``(x, y)`` pixels and costs path lengths in pixels from the root.
The tree is kept as linked lists (:data:`PARENT`, :data:`CHILD`, :data:`NEXT`, :data:`PREV`
columns of ``Tree.links``) so that re-parenting a node and shifting its subtree's costs
(:func:`reparent`) need no search. The goal, once connected, is a leaf; its cost is the best
solution cost.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numba import njit

from vnrrt.planners import spatial

PARENT, CHILD, NEXT, PREV = 0, 1, 2, 3  # columns of ``Tree.links``: the tree as linked lists
TRACE_REL = 1e-4  # relative improvement that earns a new trace point


class Tree(NamedTuple):
    """The nodes of one RRT* run, capacity ``C``: ``pts`` (C, 2) float64 positions (x, y),
    ``cost`` (C,) cost-to-come, ``links`` (C, 4) int64 parent / first child / next and
    previous sibling (-1: none), ``bnext`` (C,) and ``head`` the bucket grid
    (:mod:`.spatial`), ``step`` (C,) each node's radius of refinement moves (:mod:`.refine`)."""

    pts: np.ndarray
    cost: np.ndarray
    links: np.ndarray
    bnext: np.ndarray
    step: np.ndarray
    head: np.ndarray


class Scratch(NamedTuple):
    """Buffers of one iteration: the near set (indices, distances, costs through them,
    segment checks 0 unknown / 1 free / 2 blocked) and a stack for subtree walks."""

    near_idx: np.ndarray
    near_d: np.ndarray
    near_c: np.ndarray
    near_ok: np.ndarray
    stack: np.ndarray


class Counters(NamedTuple):
    """Mutable counts, each a (1,) int64 array: nodes in the tree, iterations (samples),
    segment checks, the goal node (-1: none yet), trace points, milestones passed."""

    nodes: np.ndarray
    iters: np.ndarray
    checks: np.ndarray
    goal: np.ndarray
    trace_len: np.ndarray
    milestone: np.ndarray


class Trace(NamedTuple):
    """The sparse best-cost trace: ``iters`` (T,) int64 and ``costs`` (T,) float64."""

    iters: np.ndarray
    costs: np.ndarray


class Arrays:
    """The arrays of one run for ``capacity`` nodes on an ``(H, W)`` map: :attr:`tree`,
    :attr:`scratch`, :attr:`counters` (views of one array), :attr:`trace` (``trace``
    points); :attr:`flat`: the same as plain tuples, as the compiled loop takes them (numba
    types a call's plain tuples of arrays about 3x faster than named tuples). Empty once
    :meth:`reset`."""

    def __init__(self, capacity: int, shape: tuple[int, int], bucket: float, trace: int):
        c = int(capacity)
        self.tree = Tree(
            np.empty((c, 2)),
            np.empty(c),
            np.empty((c, 4), np.int64),
            np.empty(c, np.int64),
            np.empty(c),
            spatial.new_buckets(shape, bucket),
        )
        buf = np.zeros(len(Counters._fields), np.int64)
        self.counters = Counters(*(buf[i : i + 1] for i in range(len(buf))))
        self.trace = Trace(np.empty(trace, np.int64), np.empty(trace))
        self._new_scratch(c)

    def _new_scratch(self, c: int) -> None:
        kinds = (np.int64, np.float64, np.float64, np.int8, np.int64)  # the fields' dtypes
        self.scratch = Scratch(*(np.empty(c, kind) for kind in kinds))
        self.flat = tuple(self.tree), tuple(self.scratch), tuple(self.counters), tuple(self.trace)

    def enlarge(self, max_iterations: int) -> None:
        """Double a full tree's room, up to the budget's (root, goal and a node per
        iteration), the tree kept: memory grows with the work done."""
        n = len(self.tree.cost)
        if n >= max_iterations + 2:
            raise RuntimeError(f"tree of {n} nodes full before the budget")
        c = min(2 * n, max_iterations + 2)
        grown = [np.empty((c, *arr.shape[1:]), arr.dtype) for arr in self.tree[:-1]]
        for new, arr in zip(grown, self.tree[:-1], strict=True):
            new[:n] = arr
        self.tree = Tree(*grown, self.tree.head)
        self._new_scratch(c)

    def reset(self) -> None:
        """Empty the tree, its arrays kept (a node's fields are written when it is added)."""
        for count in self.counters:
            count[0] = 0
        self.counters.goal[0] = -1
        self.tree.head.fill(-1)


@njit(cache=True)
def _link(links, i, parent):
    """Make ``i`` the first child of ``parent`` (its own children are kept)."""
    links[i, PARENT] = parent
    links[i, PREV] = -1
    first = links[parent, CHILD] if parent >= 0 else -1
    links[i, NEXT] = first
    if first >= 0:
        links[first, PREV] = i
    if parent >= 0:
        links[parent, CHILD] = i


@njit(cache=True, inline="always")
def add_node(tree, i, parent, x, y, c):
    """Write node ``i`` at ``(x, y)`` with cost ``c`` as a new leaf under ``parent``."""
    tree.pts[i, 0], tree.pts[i, 1], tree.cost[i] = x, y, c
    tree.links[i, CHILD] = -1
    _link(tree.links, i, parent)


@njit(cache=True, inline="always")
def reparent(tree, stack, i, parent, c):
    """Move node ``i`` under ``parent`` with new cost ``c``; shift its subtree's costs."""
    links, cost = tree.links, tree.cost
    prev, nxt = links[i, PREV], links[i, NEXT]
    if prev >= 0:
        links[prev, NEXT] = nxt
    else:
        links[links[i, PARENT], CHILD] = nxt
    if nxt >= 0:
        links[nxt, PREV] = prev
    _link(links, i, parent)
    delta = c - cost[i]
    cost[i] = c
    stack[0] = i
    top = 1
    while top > 0:  # propagate delta to every descendant
        top -= 1
        child = links[stack[top], CHILD]
        while child >= 0:
            cost[child] += delta
            stack[top] = child
            top += 1
            child = links[child, NEXT]


@njit(cache=True, inline="always")
def best_cost(tree, counters):
    """Cost of the best solution so far (``inf`` before the first)."""
    g = counters.goal[0]
    return tree.cost[g] if g >= 0 else np.inf


@njit(cache=True, inline="always")
def record(counters, tree, trace, milestones):
    """Append to the sparse trace; return True when the best cost passed a milestone.

    ``milestones`` (M,) are cost bounds in decreasing order (``inf`` = any solution).
    """
    g = counters.goal[0]
    if g < 0:
        return False
    c = tree.cost[g]
    n = counters.trace_len[0]
    if n == 0 or c < trace.costs[n - 1] * (1.0 - TRACE_REL):
        n = min(n, trace.iters.shape[0] - 1)  # when full, the last point is overwritten
        trace.iters[n], trace.costs[n] = counters.iters[0], c
        counters.trace_len[0] = n + 1
    m = counters.milestone[0]
    hit = False
    while m < milestones.shape[0] and c <= milestones[m]:
        m += 1
        hit = True
    counters.milestone[0] = m
    return hit


@njit(cache=True)
def branch(links: np.ndarray, pts: np.ndarray, node: int) -> np.ndarray:
    """Positions ``(K, 2)`` (a new array) from the root to ``node`` following parent links."""
    k, v = 0, node
    while v >= 0:
        k += 1
        v = links[v, PARENT]
    out = np.empty((k, 2))
    v = node
    for i in range(k - 1, -1, -1):
        out[i, 0], out[i, 1] = pts[v, 0], pts[v, 1]
        v = links[v, PARENT]
    return out


@njit(cache=True)
def finish(links, pts, cost, goal, trace_iters, trace_costs, k, iters_now):
    """What a finished run returns, in one compiled call: the path ``(K, 2)`` from the root to
    ``goal`` (``(0, 2)`` when ``goal`` is -1), its ``K - 1`` segment lengths (``hypot`` of the
    coordinate differences, the values :func:`vnrrt.planners.collision.polyline_length` sums),
    and the best-cost trace (iterations int64, costs float64): its ``k`` points, then the
    goal's cost at iteration ``iters_now`` when that is not the last point traced."""
    path = branch(links, pts, goal) if goal >= 0 else np.zeros((0, 2))
    segs = np.empty(max(path.shape[0] - 1, 0))
    for i in range(segs.shape[0]):
        segs[i] = math.hypot(path[i + 1, 0] - path[i, 0], path[i + 1, 1] - path[i, 1])
    last = 1 if k > 0 and goal >= 0 and trace_costs[k - 1] != cost[goal] else 0
    out_iters, out_costs = np.empty(k + last, np.int64), np.empty(k + last)
    out_iters[:k], out_costs[:k] = trace_iters[:k], trace_costs[:k]
    if last:
        out_iters[k], out_costs[k] = iters_now, cost[goal]
    return path, segs, out_iters, out_costs
