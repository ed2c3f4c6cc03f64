"""The one RRT* core (paper, Algorithm 1 / Algorithm 2), compiled with numba.

All planners (RRT*, NRRT*, VNRRT*, M-VNRRT*) run :func:`grow`; they differ only in the
:class:`~vnrrt.planners.samplers.Sampler` data passed in and in their stop rule. One
iteration is: Sample, Nearest, Steer (step ``eta``), ObstacleFree, Extend (choose the
cheapest collision-free parent among the near nodes), Rewire (re-parent near nodes
through the new node, propagating the cost change to their descendants), then try to
connect the new node to the goal point.

The tree lives in preallocated arrays (:class:`Tree`); positions are continuous
``(x, y)`` pixels, costs are path lengths in pixels from the start. The goal, once
connected, is a leaf node that is never a Nearest/near candidate, so its cost is the
best solution cost and improves through re-parenting and cost propagation.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from vnrrt.planners import spatial
from vnrrt.planners.collision import segment_free
from vnrrt.planners.samplers import sample_point

PARENT, CHILD, NEXT, PREV = 0, 1, 2, 3  # columns of ``links``: tree as linked lists
N_NODES, ITERS, CHECKS, GOAL, TRACE_LEN, MILESTONE = range(6)  # slots of ``counters``
RUNNING, MILESTONE_HIT, TREE_FULL = 0, 1, 2  # return codes of :func:`grow`
TRACE_REL = 1e-4  # relative improvement that earns a new trace point


class Tree:
    """Preallocated state of one RRT* run for at most ``capacity`` nodes.

    Arrays: ``pts`` (C, 2) float64 node positions (x, y); ``cost`` (C,) float64 cost-to-come;
    ``links`` (C, 4) int64 parent / first child / next and previous sibling (-1: none);
    ``bnext`` (C,) int64 bucket lists; ``head`` bucket heads (see :mod:`.spatial`);
    ``counters`` (6,) int64; ``trace_it``/``trace_cost`` (T,) the sparse cost trace;
    scratch buffers for near sets and subtree walks.
    """

    def __init__(self, capacity: int, shape: tuple[int, int], bucket: float, trace: int):
        c = int(capacity)
        self.pts = np.empty((c, 2))
        self.cost = np.empty(c)
        self.links = np.empty((c, 4), np.int64)
        self.bnext = np.empty(c, np.int64)
        self.head = spatial.new_buckets(shape, bucket)
        self.bucket = float(bucket)
        self.counters = np.zeros(6, np.int64)
        self.counters[GOAL] = -1
        self.trace_it = np.empty(trace, np.int64)
        self.trace_cost = np.empty(trace)
        self.near_idx = np.empty(c, np.int64)
        self.near_d = np.empty(c)
        self.near_c = np.empty(c)
        self.near_ok = np.empty(c, np.int8)
        self.stack = np.empty(c, np.int64)

    def grow(self, capacity: int) -> None:
        """Enlarge the arrays to ``capacity`` nodes, keeping the tree (memory grows with the
        work done, not with the iteration budget)."""
        c, n = int(capacity), len(self.cost)
        if c <= n:
            return
        for name in ("pts", "cost", "links", "bnext"):
            old = getattr(self, name)
            new = np.empty((c, *old.shape[1:]), old.dtype)
            new[:n] = old
            setattr(self, name, new)
        self.near_idx = np.empty(c, np.int64)
        self.near_d = np.empty(c)
        self.near_c = np.empty(c)
        self.near_ok = np.empty(c, np.int8)
        self.stack = np.empty(c, np.int64)

    @property
    def capacity(self) -> int:
        return len(self.cost)

    def add_root(self, x: float, y: float) -> None:
        """Insert the start node (index 0, cost 0)."""
        add_node(self.pts, self.cost, self.links, 0, -1, x, y, 0.0)
        spatial.insert(self.head, self.bnext, self.bucket, 0, x, y)
        self.counters[N_NODES] = 1


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


@njit(cache=True)
def add_node(pts, cost, links, i, parent, x, y, c):
    """Write node ``i`` at ``(x, y)`` with cost ``c`` as a new leaf under ``parent``."""
    pts[i, 0], pts[i, 1], cost[i] = x, y, c
    links[i, CHILD] = -1
    _link(links, i, parent)


@njit(cache=True)
def reparent(cost, links, stack, i, parent, c):
    """Move node ``i`` under ``parent`` with new cost ``c``; shift its subtree's costs."""
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


@njit(cache=True)
def choose_parent(occ, pts, cost, counters, near_idx, near_d, near_c, near_ok, k, x, y, p0, c0):
    """Extend: cheapest collision-free parent for a new node at ``(x, y)``.

    Candidates are the ``k`` near nodes, tried in order of cost-through-them; ``p0``
    (the nearest node, already checked) with cost ``c0`` is the default. Segment checks
    are cached in ``near_ok`` (0 unknown, 1 free, 2 blocked) for :func:`rewire`.
    """
    for j in range(k):
        near_c[j] = cost[near_idx[j]] + near_d[j]
        near_ok[j] = 1 if near_idx[j] == p0 else 0
    for j in np.argsort(near_c[:k]):
        if near_c[j] >= c0:
            break
        q = near_idx[j]
        counters[CHECKS] += 1
        if segment_free(occ, pts[q, 0], pts[q, 1], x, y):
            near_ok[j] = 1
            return q, near_c[j]
        near_ok[j] = 2
    return p0, c0


@njit(cache=True)
def rewire(occ, pts, cost, links, counters, stack, near_idx, near_d, near_ok, k, new):
    """Rewire: re-parent near nodes through ``new`` when that is cheaper and free."""
    for j in range(k):
        q = near_idx[j]
        c = cost[new] + near_d[j]
        if q == links[new, PARENT] or c >= cost[q] - 1e-9:
            continue
        ok = near_ok[j]
        if ok == 0:
            counters[CHECKS] += 1
            ok = 1 if segment_free(occ, pts[q, 0], pts[q, 1], pts[new, 0], pts[new, 1]) else 2
        if ok == 1:
            reparent(cost, links, stack, q, new, c)


@njit(cache=True)
def connect_goal(occ, pts, cost, links, counters, stack, new, gx, gy, goal_radius):
    """Connect (or re-parent) the goal leaf to ``new`` when within reach, cheaper, free."""
    d = math.hypot(gx - pts[new, 0], gy - pts[new, 1])
    g = counters[GOAL]
    if d > goal_radius or (g >= 0 and cost[new] + d >= cost[g] - 1e-9):
        return
    counters[CHECKS] += 1
    if not segment_free(occ, pts[new, 0], pts[new, 1], gx, gy):
        return
    if g < 0:
        g = counters[N_NODES]
        add_node(pts, cost, links, g, new, gx, gy, cost[new] + d)
        counters[GOAL] = g
        counters[N_NODES] += 1
    else:
        reparent(cost, links, stack, g, new, cost[new] + d)


@njit(cache=True)
def record(counters, cost, trace_it, trace_cost, milestones):
    """Append to the sparse trace; return True when the best cost passed a milestone.

    ``milestones`` (M,) are cost bounds in decreasing order (``inf`` = any solution).
    """
    g = counters[GOAL]
    if g < 0:
        return False
    c = cost[g]
    n = counters[TRACE_LEN]
    if n == 0 or c < trace_cost[n - 1] * (1.0 - TRACE_REL):
        n = min(n, trace_it.shape[0] - 1)  # when full, the last point is overwritten
        trace_it[n], trace_cost[n] = counters[ITERS], c
        counters[TRACE_LEN] = n + 1
    m = counters[MILESTONE]
    hit = False
    while m < milestones.shape[0] and c <= milestones[m]:
        m += 1
        hit = True
    counters[MILESTONE] = m
    return hit


@njit(cache=True)
def near_radius(n, eta, gamma, fixed_radius):
    """Near radius for a tree of ``n`` nodes: ``min(gamma sqrt(log n / n), eta)``, or
    ``fixed_radius`` when ``gamma <= 0``."""
    if gamma <= 0.0:
        return fixed_radius
    n = max(n, 2)
    return min(gamma * math.sqrt(math.log(n) / n), eta)


# Slots of the float64 ``params`` array given to :func:`grow`.
P_ETA, P_GAMMA, P_RADIUS, P_GOAL_RADIUS, P_GX, P_GY, P_MIX, P_MIN_SPACING = range(8)


@njit(cache=True)
def grow(
    occ, pts, cost, links, bnext, head, bucket, counters, trace_it, trace_cost,
    near_idx, near_d, near_c, near_ok, stack, rng, cdf, last, milestones, params, n_iter,
):  # fmt: skip
    """Run up to ``n_iter`` RRT* iterations on the tree arrays (see :class:`Tree`).

    Returns :data:`MILESTONE_HIT` as soon as the best cost passes a milestone (so the
    caller can time it), :data:`TREE_FULL` when no room is left for a node and the goal,
    else :data:`RUNNING`. ``occ`` is the ``(H, W)`` uint8 grid, ``rng`` the sampler state.
    """
    h, w = occ.shape
    eta, goal_radius = params[P_ETA], params[P_GOAL_RADIUS]
    for _ in range(n_iter):
        new = counters[N_NODES]
        if new + 2 > pts.shape[0]:
            return TREE_FULL
        counters[ITERS] += 1
        sx, sy = sample_point(rng, h, w, params[P_MIX], cdf, last)
        p = spatial.nearest(head, bnext, pts, bucket, sx, sy)
        d = math.hypot(sx - pts[p, 0], sy - pts[p, 1])
        if d <= params[P_MIN_SPACING]:  # a node here would duplicate its nearest node
            continue
        t = min(1.0, eta / d)  # Steer
        x, y = pts[p, 0] + t * (sx - pts[p, 0]), pts[p, 1] + t * (sy - pts[p, 1])
        counters[CHECKS] += 1
        if not segment_free(occ, pts[p, 0], pts[p, 1], x, y):
            continue
        r = near_radius(new + 1, eta, params[P_GAMMA], params[P_RADIUS])
        k = spatial.near(head, bnext, pts, bucket, x, y, r, near_idx, near_d)
        q, c = choose_parent(
            occ, pts, cost, counters, near_idx, near_d, near_c, near_ok, k, x, y, p, cost[p] + t * d
        )
        add_node(pts, cost, links, new, q, x, y, c)
        spatial.insert(head, bnext, bucket, new, x, y)
        counters[N_NODES] += 1
        rewire(occ, pts, cost, links, counters, stack, near_idx, near_d, near_ok, k, new)
        gx, gy = params[P_GX], params[P_GY]
        connect_goal(occ, pts, cost, links, counters, stack, new, gx, gy, goal_radius)
        if record(counters, cost, trace_it, trace_cost, milestones):
            return MILESTONE_HIT
    return RUNNING


def run_chunk(
    tree: Tree,
    occ: np.ndarray,
    sampler_args: tuple[np.ndarray, int],
    rng: np.ndarray,
    milestones: np.ndarray,
    params: np.ndarray,
    n_iter: int,
) -> int:
    """Call :func:`grow` on ``tree``; ``sampler_args`` is ``(cdf, last)``."""
    t = tree
    arrays = (t.trace_it, t.trace_cost, t.near_idx, t.near_d, t.near_c, t.near_ok, t.stack)
    return grow(
        occ, t.pts, t.cost, t.links, t.bnext, t.head, t.bucket, t.counters, *arrays,
        rng, sampler_args[0], sampler_args[1], milestones, params, int(n_iter),
    )  # fmt: skip


def branch(links: np.ndarray, pts: np.ndarray, node: int) -> np.ndarray:
    """Positions ``(K, 2)`` from the root to ``node`` following parent links."""
    chain = []
    while node >= 0:
        chain.append(node)
        node = int(links[node, PARENT])
    return pts[chain[::-1]].copy()
