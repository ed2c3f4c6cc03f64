"""Informed sampling and the fast-planner options: informed draws are uniform over the
ellipse-map intersection and never outside it, heatmap draws follow the heatmap restricted
to the ellipse, skipping keeps the best path, informed RRT* still reaches 1% of the exact
optimum on trap maps, the straight segment is taken first, same seed same result."""

import math

import numpy as np
import pytest
from scipy import stats

from vnrrt.maps.named import named_map
from vnrrt.planners import any_angle_path, draw, heatmap_sampler, path_free, plan, uniform_sampler
from vnrrt.planners.samplers import HEATMAP_TRIES


def inside(points, s, g, c):
    return np.hypot(*(points - s).T) + np.hypot(*(points - g).T) <= c + 1e-9


@pytest.mark.parametrize(("s", "g", "c"), [((20.5, 30.5), (80.5, 60.5), 75.0),
                                           ((5.5, 5.5), (95.5, 5.5), 150.0)])  # fmt: skip
def test_informed_uniform_draws_are_uniform_over_the_ellipse_inside_the_map(s, g, c):
    """Chi-square over a 10 x 10 grid of bins: expected counts = the bins' areas inside both
    the ellipse and the 100 x 100 map (measured on a fine lattice)."""
    pts = draw(uniform_sampler((100, 100)), 40_000, seed=3, ellipse=(s, g, c))
    s, g = np.array(s), np.array(g)
    assert inside(pts, s, g, c).all()
    assert (pts >= 0).all() and (pts < 100).all()
    xs = (np.arange(400) + 0.5) / 4
    lattice = np.stack(np.meshgrid(xs, xs), axis=-1).reshape(-1, 2)
    area = np.histogram2d(*lattice[inside(lattice, s, g, c)].T, bins=10, range=[[0, 100]] * 2)[0]
    seen = np.histogram2d(*pts.T, bins=10, range=[[0, 100]] * 2)[0]
    keep = area > 50  # bins well inside: expected counts large enough for chi-square
    expected = area[keep] / area.sum() * len(pts)
    observed = seen[keep]
    stat = ((observed - expected) ** 2 / expected).sum()
    assert stats.chi2.sf(stat, keep.sum() - 1) > 1e-3


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


def test_skipping_keeps_the_best_path_and_costs_only_improve():
    grid = named_map("u_trap", 200).grid
    fm = named_map("u_trap", 200)
    s, g = fm.starts[0] + 0.5, fm.goals[0] + 0.5
    r = plan(grid, s, g, stop="optimal", informed=True, keep_tree=True, seed=2,
             reference_length=any_angle_path(grid, s, g)[1])  # fmt: skip
    assert r.success and path_free(grid, r.path)
    assert np.all(np.diff(r.trace_costs) <= 1e-9)  # the best cost never got worse
    f_hat = np.hypot(*(r.path - s).T) + np.hypot(*(r.path - g).T)
    assert (f_hat <= r.cost + 1e-6).all()  # its nodes are exactly those never skipped


@pytest.mark.parametrize("name", ["narrow_passage", "u_trap", "maze"])
@pytest.mark.parametrize("planner", ["rrt_star", "vnrrt_star"])
def test_informed_planners_reach_the_exact_optimum_on_trap_maps(name, planner):
    fm = named_map(name, 200)
    s, g = fm.starts[0] + 0.5, fm.goals[0] + 0.5
    exact = any_angle_path(fm.grid, s, g)[1]
    heat = np.ones(fm.grid.shape) if planner != "rrt_star" else None
    r = plan(fm.grid, s, g, planner, heatmap=heat, stop="optimal", reference_length=exact,
             informed=True, seed=0, max_seconds=20)  # fmt: skip
    assert r.success and r.cost <= 1.01 * exact + 1e-9 and path_free(fm.grid, r.path)


def test_the_straight_segment_first_is_the_optimum_at_once():
    grid = np.zeros((100, 100), np.uint8)
    s, g = (3.5, 4.5), (96.5, 91.5)
    r = plan(grid, s, g, stop="optimal", straight_first=True, reference_length=math.dist(s, g))
    assert r.success and r.iterations == 0 and r.cost == pytest.approx(math.dist(s, g))
    assert r.time_to_first == r.time_to_stop and r.tree_size == 2
    np.testing.assert_allclose(r.path, [s, g])
    tree = plan(grid, s, g, straight_first=True, keep_tree=True)
    np.testing.assert_allclose(tree.tree_points, [s, g])
    assert list(tree.tree_parents) == [-1, 0]
    # a stop bound below the straight segment cannot be met: the search runs to its budget
    short = plan(grid, s, g, stop="optimal", straight_first=True, reference_length=10.0,
                 max_iterations=300, seed=0)  # fmt: skip
    assert not short.success and short.stop_reason == "max_iterations"
    assert short.time_to_first < short.time_to_stop
    assert short.cost == pytest.approx(math.dist(s, g))
    blocked = grid.copy()
    blocked[40:60, 40:60] = 1
    r2 = plan(blocked, s, g, stop="initial", straight_first=True, seed=0)
    assert r2.iterations > 0  # no straight segment: the search runs as usual


def test_visible_goal_connection_and_same_seed_same_result():
    fm = named_map("cluttered", 200)
    s, g = fm.starts[0] + 0.5, fm.goals[0] + 0.5
    a = plan(fm.grid, s, g, stop="optimal", informed=True, goal_radius=math.inf, seed=5)
    b = plan(fm.grid, s, g, stop="optimal", informed=True, goal_radius=math.inf, seed=5)
    assert a.success and a.cost == b.cost and a.iterations == b.iterations
    np.testing.assert_array_equal(a.path, b.path)
