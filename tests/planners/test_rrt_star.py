"""Informed sampling and the fast-planner options: informed draws are uniform over the
ellipse-map intersection and never outside it (thin maps included), heatmap draws follow the
heatmap restricted to the ellipse (and fall back to uniform there), the core samples in the
ellipse only when informed and solved, nodes added after a solution can improve it (informed
skipping) and the best path is kept, informed planners reach 1% of the exact optimum on trap
maps, the straight segment is taken first, a node that sees the goal joins it at any
distance, the tree's memory follows the work done, same seed same result."""

import itertools
import math

import numpy as np
import pytest
from scipy import stats

from vnrrt.maps.named import named_map
from vnrrt.planners import (
    PlannerConfig,
    any_angle_path,
    draw,
    heatmap_sampler,
    path_free,
    plan,
    rrt_star,
    uniform_sampler,
)
from vnrrt.planners import tree as nodes
from vnrrt.planners.planner import warmup
from vnrrt.planners.run import FIRST_CAPACITY
from vnrrt.planners.samplers import HEATMAP_TRIES, rng_state


def inside(points, s, g, c):
    return np.hypot(*(points - s).T) + np.hypot(*(points - g).T) <= c + 1e-9


def costs_to_come(points, parents):
    """Path length from the root to each node of a tree given by ``parents`` (-1: root)."""
    cost = np.full(len(points), np.nan)
    for i in range(len(points)):
        chain = [i]
        while np.isnan(cost[chain[-1]]) and parents[chain[-1]] >= 0:
            chain.append(parents[chain[-1]])
        if np.isnan(cost[chain[-1]]):  # the root
            cost[chain[-1]] = 0.0
        for child, parent in zip(chain[-2::-1], chain[:0:-1], strict=True):
            cost[child] = cost[parent] + math.dist(points[child], points[parent])
    return cost


def assert_uniform_in_ellipse(pts, shape, s, g, c):
    """``pts`` lie in the ellipse (foci s, g; major axis c) and the ``(H, W)`` map, and a
    chi-square test over a 10 x 10 grid of bins does not reject uniformity: expected counts
    are the bins' areas inside both (measured on a fine lattice)."""
    h, w = shape
    s, g = np.array(s), np.array(g)
    assert inside(pts, s, g, c).all()
    assert (pts >= 0).all() and (pts[:, 0] < w).all() and (pts[:, 1] < h).all()
    lattice = np.stack(
        np.meshgrid((np.arange(4 * w) + 0.5) / 4, (np.arange(4 * h) + 0.5) / 4), axis=-1
    ).reshape(-1, 2)
    box = [[0, w], [0, h]]
    area = np.histogram2d(*lattice[inside(lattice, s, g, c)].T, bins=10, range=box)[0]
    seen = np.histogram2d(*pts.T, bins=10, range=box)[0]
    keep = area > 0.5 * area.max()  # bins well inside: expected counts large for chi-square
    expected = seen[keep].sum() * area[keep] / area[keep].sum()
    stat = ((seen[keep] - expected) ** 2 / expected).sum()
    assert stats.chi2.sf(stat, keep.sum() - 1) > 1e-3


@pytest.mark.parametrize(("shape", "s", "g", "c"), [
    ((100, 100), (20.5, 30.5), (80.5, 60.5), 75.0),  # ellipse inside the map: drawn from it
    ((100, 100), (5.5, 5.5), (95.5, 5.5), 150.0),  # half outside the map
    ((10, 400), (5.5, 5.5), (394.5, 4.5), 600.0),  # a thin map in a wide ellipse: the box
])  # fmt: skip
def test_informed_uniform_draws_are_uniform_over_the_ellipse_inside_the_map(shape, s, g, c):
    pts = draw(uniform_sampler(shape), 40_000, seed=3, ellipse=(s, g, c))
    assert_uniform_in_ellipse(pts, shape, s, g, c)


def test_heatmap_draws_without_mass_in_the_ellipse_fall_back_to_uniform_there():
    """All heatmap weight lies outside the ellipse: after HEATMAP_TRIES rejected draws each
    sample is a uniform point of the ellipse inside the map."""
    heat = np.zeros((100, 100))
    heat[80:, 80:] = 1.0
    s, g, c = (20.5, 30.5), (60.5, 40.5), 60.0
    pts = draw(heatmap_sampler(heat, (100, 100), mix=1.0), 20_000, seed=4, ellipse=(s, g, c))
    assert_uniform_in_ellipse(pts, (100, 100), s, g, c)


def test_the_core_samples_in_the_ellipse_once_a_solution_exists_and_only_when_informed():
    """:func:`vnrrt.planners.rrt_star.sample` (what every planner's iteration draws): inside the
    ellipse of ``c_best`` when informed and solved, over the whole map otherwise."""
    h, w, s, g, c_best = 100, 100, (20.5, 30.5), (60.5, 40.5), 50.0
    sampler = heatmap_sampler(np.random.default_rng(0).random((h, w)), (h, w), mix=0.5)
    draws = rrt_star.Draws(sampler.mix, sampler.cdf, sampler.last)
    p = rrt_star.Params(eta=10.0, gamma=0.0, radius=5.0, goal_radius=10.0, sx=s[0], sy=s[1],
                    gx=g[0], gy=g[1], min_spacing=0.0, bucket=5.0, informed=True)  # fmt: skip

    def points(params, cost):
        rng = rng_state(7)
        return np.array([rrt_star.sample(rng, h, w, draws, params, cost) for _ in range(4000)])

    assert inside(points(p, c_best), np.array(s), np.array(g), c_best).all()
    for params, cost in ((p, math.inf), (p._replace(informed=False), c_best)):
        pts = points(params, cost)
        assert (~inside(pts, np.array(s), np.array(g), c_best)).mean() > 0.5


def test_heatmap_draws_follow_the_heatmap_restricted_to_the_ellipse():
    """Heatmap draws are rejected outside the ellipse (at most HEATMAP_TRIES times, then a
    uniform ellipse point): the pixel frequencies match the heatmap restricted to the
    ellipse (weight x the pixel's share inside) mixed with that fallback, computed apart."""
    h = np.zeros((40, 40))
    h[10:30, 10:30] = np.random.default_rng(0).random((20, 20))
    s, g, c = np.array([5.5, 20.5]), np.array([34.5, 20.5]), 36.0
    sampler = heatmap_sampler(h, (40, 40), mix=1.0)
    pts = draw(sampler, 60_000, seed=1, ellipse=(s, g, c))
    assert inside(pts, s, g, c).all()
    sub = (np.arange(10) + 0.5) / 10  # each pixel's share inside the ellipse, 10 x 10 points
    xs = (np.arange(40)[:, None] + sub[None, :]).ravel()
    fine = np.stack(np.meshgrid(xs, xs), -1).reshape(-1, 2)
    frac = inside(fine, s, g, c).reshape(40, 10, 40, 10).mean(axis=(1, 3))  # [y, x]
    mass_in = (h * frac).sum() / h.sum()  # chance that one heatmap draw lands inside
    fallback = (1 - mass_in) ** HEATMAP_TRIES
    want = (1 - fallback) * h * frac / (h * frac).sum() + fallback * frac / frac.sum()
    cells = np.floor(pts).astype(int)
    counts = np.bincount(cells[:, 1] * 40 + cells[:, 0], minlength=1600).reshape(40, 40)
    keep = want * len(pts) > 20
    assert counts[~keep].sum() < 0.02 * len(pts)
    expected = want[keep] * len(pts)
    stat = ((counts[keep] - expected) ** 2 / expected).sum()
    assert stats.chi2.sf(stat, keep.sum() - 1) > 1e-3


@pytest.mark.parametrize("planner", ["rrt_star", "vnrrt_star"])
def test_nodes_added_after_a_solution_can_improve_it_and_the_best_path_is_kept(planner):
    """Informed skipping: a node added once a solution of cost c exists has cost-to-come
    plus straight line to the goal below c (costs only fall later), so it also lies in c's
    ellipse. The same seed first stopped at its first solution gives the tree's prefix and
    that c (>= every later best cost). Nothing is removed: the best path is a branch of the
    tree and the best cost only falls."""
    fm = named_map("u_trap", 200)
    s, g = fm.starts[0] + 0.5, fm.goals[0] + 0.5
    heat = None if planner == "rrt_star" else np.random.default_rng(1).random((200, 200))
    kw = dict(planner=planner, heatmap=heat, keep_tree=True, seed=2)
    first = plan(fm.grid, s, g, stop="initial", config=PlannerConfig(informed=True), **kw)
    r = plan(fm.grid, s, g, stop="optimal", reference_length=any_angle_path(fm.grid, s, g)[1],
             config=PlannerConfig(informed=True, max_seconds=20), **kw)  # fmt: skip
    n = first.tree_size
    np.testing.assert_array_equal(r.tree_points[:n], first.tree_points)
    assert np.array_equal(first.tree_points[-1], g)  # the goal joined last: n - 1
    later = r.tree_points[n:]
    f_hat = costs_to_come(r.tree_points, r.tree_parents)[n:] + np.hypot(*(later - g).T)
    assert len(later) > 100 and (f_hat < first.cost + 1e-9).all()
    assert inside(later, s, g, first.cost).all()
    assert r.success and path_free(fm.grid, r.path)
    assert np.all(np.diff(r.trace_costs) <= 1e-9)  # the best cost never got worse
    on_tree = (np.abs(r.path[:, None] - r.tree_points[None]).sum(-1) == 0).any(axis=1)
    assert on_tree.all()


def test_uninformed_runs_add_nodes_that_cannot_improve_the_first_solution():
    """The check above is not empty: without informed skipping the same run adds nodes
    that cannot improve the first solution."""
    fm = named_map("u_trap", 200)
    s, g = fm.starts[0] + 0.5, fm.goals[0] + 0.5
    first = plan(
        fm.grid, s, g, stop="initial", keep_tree=True, seed=2, config=PlannerConfig.paper()
    )  # the paper's settings, as r's
    r = plan(fm.grid, s, g, stop="optimal", reference_length=math.dist(s, g), keep_tree=True,
             seed=2, config=PlannerConfig(max_iterations=4000, eps=0.0))  # fmt: skip
    np.testing.assert_array_equal(r.tree_points[: first.tree_size], first.tree_points)
    later = r.tree_points[first.tree_size :]
    f_hat = costs_to_come(r.tree_points, r.tree_parents)[first.tree_size :]
    assert (f_hat + np.hypot(*(later - g).T) > first.cost).sum() > 20


@pytest.mark.parametrize("name", ["narrow_passage", "u_trap", "maze"])
@pytest.mark.parametrize("planner", ["rrt_star", "vnrrt_star"])
def test_informed_planners_reach_the_exact_optimum_on_trap_maps(name, planner):
    fm = named_map(name, 200)
    s, g = fm.starts[0] + 0.5, fm.goals[0] + 0.5
    path, exact = any_angle_path(fm.grid, s, g)
    heat = None
    if planner != "rrt_star":  # a vertex-like heatmap: blobs at the optimum's turning points
        yy, xx = np.mgrid[:200, :200] + 0.5
        blobs = [np.exp(-((xx - x) ** 2 + (yy - y) ** 2) / 18.0) for x, y in path[1:-1]]
        heat = 0.01 + np.sum(blobs, axis=0)
    for seed in range(3):
        r = plan(fm.grid, s, g, planner, heatmap=heat, stop="optimal", reference_length=exact,
                 config=PlannerConfig(informed=True, max_seconds=20), seed=seed)  # fmt: skip
        assert r.success and r.cost <= 1.01 * exact + 1e-9 and path_free(fm.grid, r.path)


def test_the_straight_segment_first_is_the_optimum_at_once():
    grid = np.zeros((100, 100), np.uint8)
    s, g = (3.5, 4.5), (96.5, 91.5)
    first = PlannerConfig(straight_first=True)
    r = plan(grid, s, g, stop="optimal", config=first, reference_length=math.dist(s, g))
    assert r.success and r.iterations == 0 and r.cost == pytest.approx(math.dist(s, g))
    assert r.time_to_first == r.time_to_stop and r.tree_size == 2
    np.testing.assert_allclose(r.path, [s, g])
    tree = plan(grid, s, g, config=first, keep_tree=True)
    np.testing.assert_allclose(tree.tree_points, [s, g])
    assert list(tree.tree_parents) == [-1, 0]
    # a stop bound below the straight segment cannot be met: an error naming the argument
    with pytest.raises(ValueError, match="reference_length 10.0: .* below the straight-line"):
        plan(grid, s, g, stop="optimal", reference_length=10.0, seed=0, config=first)
    blocked = grid.copy()
    blocked[40:60, 40:60] = 1
    r2 = plan(blocked, s, g, stop="initial", config=first, seed=0)
    assert r2.iterations > 0  # no straight segment: the search runs as usual


@pytest.mark.parametrize("straight_first", [False, True])
@pytest.mark.parametrize("budget", [1, 2, 5, 40])
def test_an_unreachable_bound_runs_exactly_the_iteration_budget(budget, straight_first):
    """With the goal joined as soon as it is seen (any-distance goal radius) and nearly every
    iteration adding a node (a map empty but for a block on the straight segment, whose
    length at eps 0 is the bound: never met), the tree has room for the whole budget."""
    grid = np.zeros((100, 100), np.uint8)
    grid[44:52, 46:54] = 1  # around the segment's midpoint (50, 48)
    s, g = (3.5, 4.5), (96.5, 91.5)
    cfg = PlannerConfig(goal_radius=math.inf, straight_first=straight_first,
                        max_iterations=budget, eps=0.0)  # fmt: skip
    r = plan(grid, s, g, stop="optimal", reference_length=math.dist(s, g), config=cfg)
    assert r.stop_reason == "max_iterations" and r.iterations == budget


def test_tree_memory_follows_the_work_done_not_the_budget(monkeypatch):
    """A first solution found in a few hundred iterations allocates FIRST_CAPACITY nodes,
    even with a budget of a billion iterations; a longer run doubles the room when full,
    up to the budget (+ root and goal)."""
    warmup()  # its own small runs first
    sizes = []

    def recorded(method):
        def call(arrays, *args):
            method(arrays, *args)
            sizes.append(len(arrays.tree.cost))

        return call

    monkeypatch.setattr(nodes.Arrays, "__init__", recorded(nodes.Arrays.__init__))
    monkeypatch.setattr(nodes.Arrays, "enlarge", recorded(nodes.Arrays.enlarge))
    fm = named_map("cluttered", 200)
    s, g = fm.starts[0] + 0.5, fm.goals[0] + 0.5
    r = plan(fm.grid, s, g, config=PlannerConfig(max_iterations=10**9), seed=0)
    assert r.success and sizes == [FIRST_CAPACITY] and r.tree_size < FIRST_CAPACITY
    sizes.clear()
    r = plan(fm.grid, s, g, stop="optimal", reference_length=math.dist(s, g),
             config=PlannerConfig(max_iterations=10_000, eps=0.0))  # fmt: skip
    assert r.stop_reason == "max_iterations" and r.iterations == 10_000
    assert sizes[0] == FIRST_CAPACITY and len(sizes) > 1
    assert all(b == min(2 * a, 10_002) for a, b in itertools.pairwise(sizes))
    assert sizes[-2] < r.tree_size <= sizes[-1]  # each enlargement was needed


def test_a_node_that_sees_the_goal_connects_at_any_distance():
    """With ``goal_radius=.inf`` the first solution's last edge may be longer than the Steer
    step (a node far away saw the goal); with the default radius (eta) it never is."""
    fm = named_map("cluttered", 200)
    s, g = fm.starts[0] + 0.5, fm.goals[0] + 0.5
    last = []
    for radius in (math.inf, None):
        cfg = PlannerConfig(goal_radius=radius)
        edges = [np.linalg.norm(np.diff(plan(fm.grid, s, g, config=cfg, seed=k).path[-2:],
                                        axis=0)) for k in range(5)]  # fmt: skip
        last.append(max(edges))
    assert last[0] > 2 * 10.0 and last[1] <= 10.0 + 1e-9


@pytest.mark.parametrize("planner", ["rrt_star", "nrrt_star", "vnrrt_star", "m_vnrrt_star"])
def test_same_seed_same_result_for_every_informed_planner(planner):
    fm = named_map("cluttered", 200)
    s, g = fm.starts[0] + 0.5, fm.goals[0] + 0.5
    heat = None if planner == "rrt_star" else np.random.default_rng(3).random((200, 200))
    cfg = PlannerConfig(tau=0.5, informed=True, goal_radius=math.inf, straight_first=True,
                        max_iterations=3000)  # fmt: skip
    kw = dict(planner=planner, heatmap=heat, stop="optimal", config=cfg)
    a, b, c = (plan(fm.grid, s, g, seed=k, **kw) for k in (5, 5, 6))
    assert a.cost == b.cost and a.iterations == b.iterations
    np.testing.assert_array_equal(a.path, b.path)
    np.testing.assert_array_equal(a.trace_costs, b.trace_costs)
    assert (a.iterations, a.cost) != (c.iterations, c.cost)  # the seed matters
