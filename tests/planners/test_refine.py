"""Path refinement and pulled parents (our fastest settings): the kernels on hand-made trees
against hand-computed answers, and whole runs whose trees stay valid (free edges, exact
costs-to-come, the path a branch) while reaching the exact optimum in far fewer iterations."""

import math

import numpy as np
import pytest

from vnrrt.maps.named import named_map
from vnrrt.planners import (
    FASTEST,
    PlannerConfig,
    PlannerConfigError,
    any_angle_path,
    path_free,
    plan,
    refine,
    rrt_star,
    spatial,
)
from vnrrt.planners import tree as nodes
from vnrrt.planners.collision import segment_free
from vnrrt.planners.samplers import rng_state


def wall() -> np.ndarray:
    """40x40, a wall at x = 19..20 from y = 10 down to the bottom."""
    g = np.zeros((40, 40), np.uint8)
    g[10:, 19:21] = 1
    return g


def chain(points, goal_last=True):
    """A tree that is one chain root -> ... -> last through ``points``, with its counters."""
    arrays = nodes.Arrays(64, (40, 40), 5.0, 8)
    arrays.reset()
    t, c = arrays.tree, arrays.counters
    parent, cost = -1, 0.0
    for i, (x, y) in enumerate(points):
        if i:
            cost += math.dist(points[i - 1], (x, y))
        nodes.add_node(t, i, parent, x, y, cost)
        spatial.insert(t.head, t.bnext, 5.0, i, x, y)
        t.step[i] = 4.0
        parent = i
    c.nodes[0] = len(points)
    c.goal[0] = len(points) - 1 if goal_last else -1
    return t, c


def params(**over) -> rrt_star.Params:
    base = dict(eta=10.0, gamma=0.0, radius=5.0, goal_radius=10.0, sx=5.5, sy=30.5, gx=34.5,
                gy=30.5, min_spacing=0.0, bucket=5.0, informed=True, refine=1.0)  # fmt: skip
    return rrt_star.Params(**{**base, **over})


def branch_costs(t, n):
    """Costs-to-come recomputed from positions along parent links."""
    out = np.zeros(n)
    for i in range(n):
        v, total = i, 0.0
        while t.links[v, nodes.PARENT] >= 0:
            p = t.links[v, nodes.PARENT]
            total += math.dist(t.pts[v], t.pts[p])
            v = p
        out[i] = total
    return out


def test_pull_up_takes_the_furthest_ancestor_that_sees_the_node():
    """A chain round the wall's top end: from the chosen parent, the walk goes up while the
    ancestor sees the new point, and stops at the first that does not."""
    g = wall()
    pts = [(5.5, 30.5), (10.5, 12.5), (15.5, 8.5), (19.5, 8.5), (23.5, 9.5)]
    t, c = chain(pts, goal_last=False)
    x, y = 30.5, 9.0  # seen from (15.5, 8.5) and (19.5, 8.5); (10.5, 12.5) is behind the wall
    assert not segment_free(g, 10.5, 12.5, x, y) and segment_free(g, 15.5, 8.5, x, y)
    q, cost = rrt_star.pull_up(g, t, c, 4, t.cost[4] + math.dist(pts[4], (x, y)), x, y)
    assert q == 2 and cost == pytest.approx(t.cost[2] + math.dist(pts[2], (x, y)))
    q, _ = rrt_star.pull_up(g, t, c, 0, 1.0, x, y)  # the root has no parent: it stays
    assert q == 0


def test_a_free_shortcut_drops_the_middle_vertex():
    g = np.zeros((40, 40), np.uint8)
    pts = [(5.5, 30.5), (20.5, 5.5), (34.5, 30.5)]
    t, c = chain(pts)
    stack = np.empty(64, np.int64)
    moved = refine.refine_step(g, t, stack, c, params(), rng_state(0), 40, 40)
    assert moved == refine.IMPROVED
    assert t.links[2, nodes.PARENT] == 0 and t.cost[2] == pytest.approx(29.0)


def block() -> np.ndarray:
    """40x40, a block x in [15, 25), y in [15, 40): round it, one convex corner, (15, 15)."""
    g = np.zeros((40, 40), np.uint8)
    g[15:, 15:25] = 1
    return g


def test_perturb_moves_only_shorten_and_bring_the_bend_to_the_corner():
    """The path can only improve by moving its bend towards the block's corner: every
    accepted move lowers the goal's cost and keeps the path free and its costs exact, and
    the moves bring the bend to the corner, the cost to the exact optimum."""
    g = block()
    pts = [(5.5, 35.5), (8.5, 8.5), (35.5, 5.5)]
    t, c = chain(pts)
    stack, rng, p = np.empty(64, np.int64), rng_state(1), params(sx=5.5, sy=35.5, gx=35.5, gy=5.5)
    corners, exact = any_angle_path(g, pts[0], pts[-1])
    np.testing.assert_allclose(corners[1], (15.0, 15.0))
    costs = [t.cost[2]]
    for _ in range(300):
        refine.refine_step(g, t, stack, c, p, rng, 40, 40)
        costs.append(t.cost[2])
    assert np.all(np.diff(costs) <= 0) and costs[-1] < costs[0]
    path = nodes.branch(t.links, t.pts, 2)
    assert path_free(g, path)
    n = int(c.nodes[0])
    np.testing.assert_allclose(t.cost[:n], branch_costs(t, n), atol=1e-9)
    assert len(path) == 3 and math.dist(path[1], (15.0, 15.0)) < 0.5
    assert exact <= costs[-1] <= 1.01 * exact


@pytest.mark.parametrize("name", ["u_trap", "narrow_passage", "cluttered"])
def test_fastest_runs_keep_a_valid_tree_and_reach_the_optimum(name):
    """With every option on, the tree is still a tree of free edges with exact costs, the
    path is a branch of it, and 1% of the exact optimum is reached."""
    fm = named_map(name, 200)
    s, e = tuple(fm.starts[0] + 0.5), tuple(fm.goals[0] + 0.5)
    exact = any_angle_path(fm.grid, s, e)[1]
    for seed in range(3):
        r = plan(fm.grid, s, e, stop="optimal", reference_length=exact, config=FASTEST,
                 seed=seed, keep_tree=True)  # fmt: skip
        assert r.success and exact - 1e-9 <= r.cost <= 1.01 * exact
        pts, par = r.tree_points, r.tree_parents
        assert all(segment_free(fm.grid, *pts[par[i]], *pts[i]) for i in range(1, len(pts)))
        on_tree = (np.abs(r.path[:, None] - pts[None]).sum(-1) == 0).any(axis=1)
        assert on_tree.all() and np.all(np.diff(r.trace_costs) <= 1e-9)


def test_refinement_reaches_one_percent_in_far_fewer_iterations():
    """On the U trap, informed RRT* needs many samples to pull its path taut round the
    corners; refinement moves do it directly (median over seeds, same seeds)."""
    fm = named_map("u_trap", 200)
    s, e = tuple(fm.starts[0] + 0.5), tuple(fm.goals[0] + 0.5)
    exact = any_angle_path(fm.grid, s, e)[1]
    plain = FASTEST.replace(refine=0.0, pull_parents=False, refine_branches=0.0)
    its = {}
    for label, cfg in (("plain", plain), ("fastest", FASTEST)):
        runs = [plan(fm.grid, s, e, stop="optimal", reference_length=exact, config=cfg, seed=k)
                for k in range(5)]  # fmt: skip
        assert all(r.success for r in runs)
        its[label] = np.median([r.iterations for r in runs])
    assert its["fastest"] < 0.5 * its["plain"]


@pytest.mark.parametrize("change", [{"refine": 1.5}, {"refine_branches": -0.1},
                                    {"pull_parents": 1}])  # fmt: skip
def test_bad_refinement_settings_are_named(change):
    with pytest.raises(PlannerConfigError, match=next(iter(change))):
        PlannerConfig().replace(**change)
