"""RRT*: the one core of every planner (paper, Algorithm 1 / Algorithm 2), compiled with numba.

All planners (RRT*, NRRT*, VNRRT*, M-VNRRT*, and their informed variants) run :func:`grow`;
they differ only in the :class:`Draws` (the sampler) and :class:`Params` passed in and in
their stop rule. One iteration is: Sample, Nearest, Steer (step ``eta``), ObstacleFree,
Extend (choose the cheapest collision-free parent among the near nodes), Rewire (re-parent
near nodes through the new node, propagating the cost change to their descendants), then
try to connect the new node to the goal point. The options (:class:`vnrrt.planners.
PlannerConfig`): **informed**, once a solution of cost ``c_best`` exists, samples inside its
ellipse (:func:`.samplers.any_point`) and skips a near node ``q`` with ``|q - start| + |q -
goal| > c_best`` as parent or rewiring candidate, and a new node whose cost-to-come plus its
straight line to the goal exceeds ``c_best``; **gaps** (:func:`with_gaps`), **refine**
(:mod:`.refine`) and **pull_parents** (:func:`pull_up`).

The tree lives in preallocated arrays (:mod:`.tree`); positions are continuous ``(x, y)``
pixels, costs are path lengths in pixels from the start. The goal, once connected, is a
leaf node that is never a Nearest/near candidate, so its cost is the best solution cost
and improves through re-parenting and cost propagation.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numba import njit

from vnrrt.planners import spatial
from vnrrt.planners.collision import segment_free
from vnrrt.planners.gaps import gap_cells
from vnrrt.planners.refine import AT_REST, IMPROVED, refine_step
from vnrrt.planners.samplers import Draws, any_point, next_double
from vnrrt.planners.tree import PARENT, add_node, best_cost, record, reparent

RUNNING, MILESTONE_HIT, TREE_FULL = 0, 1, 2  # return codes of :func:`grow`


class Params(NamedTuple):
    """Settings of a run (lengths in pixels): Steer step, near-radius rule (``gamma > 0``:
    shrinking ``min(gamma sqrt(log n / n), eta)``, else ``radius``), goal connection
    radius (``inf``: any node that sees the goal), start and goal, min spacing, bucket
    side, informed sampling and skipping, the refinement shares and pulled parents
    (:class:`vnrrt.planners.PlannerConfig`)."""

    eta: float
    gamma: float
    radius: float
    goal_radius: float
    sx: float
    sy: float
    gx: float
    gy: float
    min_spacing: float
    bucket: float
    informed: bool
    refine: float = 0.0
    pull_parents: bool = False
    refine_branches: float = 0.0


@njit(cache=True)
def gaps_due(d, iters):
    """Iterations that may run before the gap cells of ``d`` must be found (a large number
    when they are not pending), given ``iters`` done."""
    return d.gap_after - iters if d.n_gaps < 0 else 1 << 62


@njit(cache=True)
def with_gaps(occ, d):
    """``d`` with the gap cells of ``occ`` found (:func:`vnrrt.planners.gaps.gap_cells`)."""
    cells = gap_cells(occ, d.gap_width)
    return Draws(d.mix, d.cdf, d.last, d.gap_share, d.gap_width, d.gap_after, cells, cells.size)


@njit(cache=True, inline="always")
def hopeless(p, x, y, c_best):
    """True when no path through ``(x, y)`` can beat ``c_best`` (informed skipping)."""
    return p.informed and math.hypot(x - p.sx, y - p.sy) + math.hypot(x - p.gx, y - p.gy) > c_best


@njit(cache=True, inline="always")
def choose_parent(occ, tree, scratch, counters, p, k, x, y, p0, c0, c_best):
    """Extend: cheapest collision-free parent for a new node at ``(x, y)`` among the ``k``
    near nodes, tried in order of cost-through-them; ``p0`` (the nearest node, already
    checked) with cost ``c0`` is the default. Segment checks are cached in
    ``scratch.near_ok`` for :func:`rewire`."""
    idx, dist, through, ok = scratch.near_idx, scratch.near_d, scratch.near_c, scratch.near_ok
    pts, cost = tree.pts, tree.cost  # (arrays taken out of the tuples once, not per node)
    for j in range(k):
        q = idx[j]
        through[j] = cost[q] + dist[j]
        ok[j] = 1 if q == p0 else 0
        if q != p0 and hopeless(p, pts[q, 0], pts[q, 1], c_best):
            ok[j] = 2  # skipped: no candidate
    for j in np.argsort(through[:k]):
        if through[j] >= c0:
            break
        if ok[j] == 2:
            continue
        q = idx[j]
        counters.checks[0] += 1
        if segment_free(occ, pts[q, 0], pts[q, 1], x, y):
            ok[j] = 1
            return q, through[j]
        ok[j] = 2
    return p0, c0


@njit(cache=True, inline="always")
def pull_up(occ, tree, counters, q, c, x, y):
    """Theta*'s any-angle parent (Nash et al. 2007): from the chosen parent ``q`` (cost ``c``
    through it), walk up to its parent while that one sees ``(x, y)``; returns the last
    ancestor that does and the cost through it (never higher: triangle inequality)."""
    while True:
        a = tree.links[q, PARENT]
        if a < 0:
            return q, c
        counters.checks[0] += 1
        if not segment_free(occ, tree.pts[a, 0], tree.pts[a, 1], x, y):
            return q, c
        q, c = a, tree.cost[a] + math.hypot(x - tree.pts[a, 0], y - tree.pts[a, 1])


@njit(cache=True, inline="always")
def rewire(occ, tree, scratch, counters, k, new):
    """Rewire: re-parent near nodes through ``new`` when that is cheaper and free (nodes
    skipped by :func:`choose_parent` stay as they are)."""
    idx, dist, known = scratch.near_idx, scratch.near_d, scratch.near_ok
    pts, cost, links = tree.pts, tree.cost, tree.links  # (taken out of the tuples once)
    for j in range(k):
        q = idx[j]
        c = cost[new] + dist[j]
        if q == links[new, PARENT] or c >= cost[q] - 1e-9:
            continue
        ok = known[j]
        if ok == 0:
            counters.checks[0] += 1
            free = segment_free(occ, pts[q, 0], pts[q, 1], pts[new, 0], pts[new, 1])
            ok = 1 if free else 2
        if ok == 1:
            reparent(tree, scratch.stack, q, new, c)


@njit(cache=True, inline="always")
def connect_goal(occ, tree, counters, stack, p, new):
    """Connect (or re-parent) the goal leaf to ``new`` when within ``p.goal_radius``,
    cheaper and free."""
    d = math.hypot(p.gx - tree.pts[new, 0], p.gy - tree.pts[new, 1])
    g = counters.goal[0]
    if d > p.goal_radius or (g >= 0 and tree.cost[new] + d >= tree.cost[g] - 1e-9):
        return
    counters.checks[0] += 1
    if not segment_free(occ, tree.pts[new, 0], tree.pts[new, 1], p.gx, p.gy):
        return
    if g < 0:
        g = counters.nodes[0]
        add_node(tree, g, new, p.gx, p.gy, tree.cost[new] + d)
        counters.goal[0] = g
        counters.nodes[0] += 1
    else:
        reparent(tree, stack, g, new, tree.cost[new] + d)


@njit(cache=True)
def straight_cost(occ, sx, sy, gx, gy):
    """The cost of the goal joined to a root at the start when the start-goal segment is
    free: the distance as :func:`connect_goal` computes it (bit for bit); -1 when blocked."""
    if not segment_free(occ, sx, sy, gx, gy):
        return -1.0
    return 0.0 + math.hypot(gx - sx, gy - sy)


@njit(cache=True)
def plant(occ, tree, counters, stack, trace, p, milestones):
    """The root at the start, the goal joined to it when ``p`` allows (:func:`connect_goal`)
    and the trace started: one compiled call, so a free straight segment costs microseconds."""
    add_node(tree, 0, -1, p.sx, p.sy, 0.0)
    spatial.insert(tree.head, tree.bnext, p.bucket, 0, p.sx, p.sy)
    counters.nodes[0] = 1
    connect_goal(occ, tree, counters, stack, p, 0)
    record(counters, tree, trace, milestones)


@njit(cache=True, inline="always")
def near_radius(n, p):
    """Near radius for a tree of ``n`` nodes: ``min(gamma sqrt(log n / n), eta)``, or the
    fixed ``radius`` when ``gamma <= 0``."""
    if p.gamma <= 0.0:
        return p.radius
    n = max(n, 2)
    return min(p.gamma * math.sqrt(math.log(n) / n), p.eta)


@njit(cache=True, inline="always")
def sample(rng, h, w, draws, p, c_best):
    """Sample: the sampler's (or the gap sampler's) draw, inside the informed ellipse once
    a solution exists (:func:`vnrrt.planners.samplers.any_point`)."""
    ellipse = (p.informed and c_best < np.inf, p.sx, p.sy, p.gx, p.gy, c_best)
    return any_point(rng, h, w, draws, ellipse)


@njit(cache=True)
def grow(occ, tree, scratch, counters, trace, rng, draws, milestones, p, n_iter):
    """Run up to ``n_iter`` RRT* iterations (module doc) on ``tree``.

    Returns :data:`MILESTONE_HIT` as soon as the best cost passes a milestone (so the
    caller can time it), :data:`TREE_FULL` when no room is left for a node (and the goal,
    while unconnected), else :data:`RUNNING`. ``occ`` is the ``(H, W)`` uint8 grid, ``rng``
    the sampler state.
    """
    h, w = occ.shape
    pts = tree.pts  # (taken out of the tuple once, not at every use)
    for _ in range(n_iter):
        new = counters.nodes[0]
        if new + (1 if counters.goal[0] >= 0 else 2) > pts.shape[0]:
            return TREE_FULL
        counters.iters[0] += 1
        c_best = best_cost(tree, counters)
        if p.refine > 0.0 and c_best < np.inf and next_double(rng) < p.refine:
            moved = refine_step(occ, tree, scratch.stack, counters, p, rng, h, w)
            if moved == IMPROVED and record(counters, tree, trace, milestones):
                return MILESTONE_HIT
            if moved != AT_REST:
                continue
        sx, sy = sample(rng, h, w, draws, p, c_best)
        near = spatial.nearest(tree.head, tree.bnext, pts, p.bucket, sx, sy)
        d = math.hypot(sx - pts[near, 0], sy - pts[near, 1])
        if d <= p.min_spacing:  # a node here would duplicate its nearest node
            continue
        t = min(1.0, p.eta / d)  # Steer
        x = pts[near, 0] + t * (sx - pts[near, 0])
        y = pts[near, 1] + t * (sy - pts[near, 1])
        counters.checks[0] += 1
        if not segment_free(occ, pts[near, 0], pts[near, 1], x, y):
            continue
        r = near_radius(new + 1, p)
        k = spatial.near(
            tree.head, tree.bnext, pts, p.bucket, x, y, r, scratch.near_idx, scratch.near_d
        )
        q, c = choose_parent(
            occ, tree, scratch, counters, p, k, x, y, near, tree.cost[near] + t * d, c_best
        )
        if p.pull_parents:
            q, c = pull_up(occ, tree, counters, q, c, x, y)
        if p.informed and c + math.hypot(p.gx - x, p.gy - y) >= c_best:
            continue  # no path through this node can improve the solution
        add_node(tree, new, q, x, y, c)
        tree.step[new] = 0.25 * p.eta  # the first radius of a refinement move (.refine)
        spatial.insert(tree.head, tree.bnext, p.bucket, new, x, y)
        counters.nodes[0] += 1
        rewire(occ, tree, scratch, counters, k, new)
        connect_goal(occ, tree, counters, scratch.stack, p, new)
        if record(counters, tree, trace, milestones):
            return MILESTONE_HIT
    return RUNNING
