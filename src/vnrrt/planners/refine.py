"""Path refinement: local moves on the best path, interleaved with the RRT* iterations.

Once a solution exists, ``Params.refine`` of the iterations (:func:`vnrrt.planners.rrt_star.grow`)
pick a random interior vertex ``v`` of the best path (or, ``Params.refine_branches`` of them,
of the branch from the root to a random tree node whose cost-to-come plus straight line to the
goal is below the best cost: a path through it could still win), between its parent ``a`` and
its child ``b`` on that path, and try, in turn:

* **shortcut**: when the segment ``a-b`` is free, ``b`` is re-parented to ``a`` (``v`` stays
  in the tree, off the path): the path loses a vertex and gets shorter (triangle inequality);
* **perturb**: a point ``x`` drawn uniformly in the disk of radius ``step[v]`` around ``v``
  replaces ``v`` on the path when ``|a x| + |x b| < |a v| + |v b|`` and both segments are
  free: ``x`` joins the tree under ``a`` and ``b`` is re-parented to it. A success gives
  ``x`` a radius :data:`GROW` x ``step[v]`` (up to ``eta``); a miss shrinks ``step[v]`` by
  :data:`SHRINK`, so each vertex's radius follows the scale at which it can still improve
  (a (1+1) evolution strategy's step-size rule). A vertex whose radius fell below
  :data:`SETTLED` is at rest: drawing it gives the iteration back to the RRT* sample.

Moves on other branches let a path of another homotopy class become as taut as the best one
before it can win. Every move keeps the tree a tree of free segments with exact costs
(:func:`reparent` propagates the change to the subtree), so the returned path is still a
branch of it and exact-collision-free. The moves pull the path taut and its bends towards
the obstacle corners where the optimum bends, which the random samples alone approach
slowly; the samples keep searching the other homotopy classes (inside the informed ellipse).
"""

from __future__ import annotations

import math

from numba import njit

from vnrrt.planners import spatial
from vnrrt.planners.collision import segment_free
from vnrrt.planners.samplers import next_double
from vnrrt.planners.tree import PARENT, add_node, reparent

SHRINK, GROW, SETTLED = 0.8, 2.0, 1e-2  # step-size rule of perturb moves (module doc)
UNCHANGED, IMPROVED, AT_REST = 0, 1, 2  # outcomes of :func:`refine_step`


@njit(cache=True)
def path_nodes(tree, goal, out):
    """The best path's nodes into ``out``, goal first, root last; returns their count."""
    k, v = 0, goal
    while v >= 0:
        out[k] = v
        k += 1
        v = tree.links[v, PARENT]
    return k


@njit(cache=True)
def _dist(tree, i, x, y):
    return math.hypot(x - tree.pts[i, 0], y - tree.pts[i, 1])


@njit(cache=True)
def refine_step(occ, tree, stack, counters, p, rng, h, w):
    """One move (module doc) on the best path; ``stack`` is scratch room for the path and the
    subtree walks. Returns :data:`IMPROVED` when the best cost fell, :data:`AT_REST` when
    the vertex drawn has settled (its radius below :data:`SETTLED`, no shortcut: the
    iteration is better spent on a sample), else :data:`UNCHANGED`."""
    goal = end = counters.goal[0]
    if p.refine_branches > 0.0 and next_double(rng) < p.refine_branches:
        end = 1 + int(next_double(rng) * (counters.nodes[0] - 1))  # any node's branch
        if tree.cost[end] + _dist(tree, end, p.gx, p.gy) >= tree.cost[goal]:
            return AT_REST  # no path through it can beat the best one: not worth a move
    k = path_nodes(tree, end, stack)
    if k < 3:
        return AT_REST
    j = 1 + int(next_double(rng) * (k - 2))  # an interior vertex, uniformly
    b, v, a = stack[j - 1], stack[j], stack[j + 1]
    ax, ay, bx, by = tree.pts[a, 0], tree.pts[a, 1], tree.pts[b, 0], tree.pts[b, 1]
    counters.checks[0] += 1
    if segment_free(occ, ax, ay, bx, by):  # shortcut
        reparent(tree, stack, b, a, tree.cost[a] + _dist(tree, a, bx, by))
        return IMPROVED
    r = tree.step[v]
    if r < SETTLED:
        return AT_REST
    rho, th = r * math.sqrt(next_double(rng)), 2.0 * math.pi * next_double(rng)
    x, y = tree.pts[v, 0] + rho * math.cos(th), tree.pts[v, 1] + rho * math.sin(th)
    ca = tree.cost[a] + _dist(tree, a, x, y)
    cb = ca + _dist(tree, b, x, y)
    better = 0.0 <= x < w and 0.0 <= y < h and cb < tree.cost[b] - 1e-9
    if better:
        counters.checks[0] += 2
        better = segment_free(occ, ax, ay, x, y) and segment_free(occ, x, y, bx, by)
    if not better:
        tree.step[v] = SHRINK * r
        return UNCHANGED
    new = counters.nodes[0]
    add_node(tree, new, a, x, y, ca)
    tree.step[new] = min(GROW * r, p.eta)
    spatial.insert(tree.head, tree.bnext, p.bucket, new, x, y)
    counters.nodes[0] += 1
    reparent(tree, stack, b, new, cb)
    return IMPROVED
