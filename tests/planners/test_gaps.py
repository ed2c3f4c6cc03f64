"""The gap sampler (planners/gaps.py, samplers.any_point, PlannerConfig.gap_share): its cells
against a brute-force reference, its draws, and its runs through the planner's results."""

import math

import numpy as np
import pytest

from vnrrt.planners import (
    FASTEST,
    PlannerConfig,
    PlannerConfigError,
    draw,
    path_free,
    plan,
    uniform_sampler,
)
from vnrrt.planners.gaps import gap_cells

NO_GAPS = FASTEST.replace(gap_share=0.0)  # our best configuration without the gap sampler


def brute_gaps(occ: np.ndarray, width: int) -> np.ndarray:
    """Free cells whose free run along the row or the column (walked cell by cell from the
    cell, the map border ending it) is at most ``width`` long; flat indices."""
    h, w = occ.shape
    out = []
    for y in range(h):
        for x in range(w):
            if occ[y, x]:
                continue
            runs = []
            for dx, dy in ((1, 0), (0, 1)):
                n = 1
                for sign in (1, -1):
                    cx, cy = x + sign * dx, y + sign * dy
                    while 0 <= cx < w and 0 <= cy < h and occ[cy, cx] == 0:
                        n, cx, cy = n + 1, cx + sign * dx, cy + sign * dy
                runs.append(n)
            if min(runs) <= width:
                out.append(y * w + x)
    return np.array(out, np.int64)


def slit_map(size: int = 60, gap_row: int = 31) -> np.ndarray:
    """A wall 2 cells thick across the map at x = 30-31 with a one-cell hole at ``gap_row``."""
    g = np.zeros((size, size), np.uint8)
    g[:, 30:32] = 1
    g[gap_row, 30:32] = 0
    return g


def test_gap_cells_match_a_brute_force_reference():
    rng = np.random.default_rng(3)
    for _ in range(200):
        h, w = rng.integers(2, 16, 2)
        occ = (rng.random((h, w)) < rng.random()).astype(np.uint8)
        for width in (1, 2, 3, 6):
            np.testing.assert_array_equal(gap_cells(occ, width), brute_gaps(occ, width))


def test_gap_cells_of_a_slit_are_the_slit():
    """The hole's two cells, nothing in open space or beside the wall; a corridor between
    an obstacle and the map border counts (the border is an obstacle)."""
    g = slit_map()
    np.testing.assert_array_equal(gap_cells(g, 8), [31 * 60 + 30, 31 * 60 + 31])
    assert gap_cells(np.zeros((40, 40), np.uint8), 8).size == 0
    g = np.zeros((40, 40), np.uint8)
    g[3, 5:35] = 1  # rows 0-2 above it: a 3-cell corridor along the top border
    cells = gap_cells(g, 3)
    assert set(cells // 40) == {0, 1, 2} and set(cells % 40) == set(range(5, 35))


def test_gap_draws_fall_in_gap_cells_in_their_share():
    """share 1: every draw lies in a gap cell; share 0.3 on a map where gap cells are 2 of
    3,600: the gap draws' share is 0.3 within a 5-sigma binomial bound; share 0: the
    sampler's own draws, bit for bit."""
    g = slit_map()
    cells = gap_cells(g, 8)
    s = uniform_sampler(g.shape)

    def in_gaps(pts):
        flat = np.floor(pts[:, 1]).astype(int) * 60 + np.floor(pts[:, 0]).astype(int)
        return np.isin(flat, cells)

    assert in_gaps(draw(s, 2000, seed=1, gaps=(1.0, cells))).all()
    n, share = 20000, 0.3
    frac = in_gaps(draw(s, n, seed=2, gaps=(share, cells))).mean()
    assert abs(frac - share) < 5 * math.sqrt(share * (1 - share) / n) + 2 / 3600
    np.testing.assert_array_equal(draw(s, 500, seed=4, gaps=(0.0, cells)), draw(s, 500, seed=4))


def test_informed_gap_draws_stay_in_the_ellipse():
    """Informed: every draw in the ellipse; the slit lies in it, so the gap draws keep their
    share (0.5 within a 5-sigma binomial bound, plus the uniform draws that land there)."""
    g = slit_map()
    cells = gap_cells(g, 8)
    start, goal, c_best = (5.5, 31.5), (55.5, 31.5), 52.0
    n = 4000
    pts = draw(uniform_sampler(g.shape), n, seed=5, ellipse=(start, goal, c_best),
               gaps=(0.5, cells))  # fmt: skip
    d = np.hypot(*(pts - start).T) + np.hypot(*(pts - goal).T)
    assert (d <= c_best + 1e-9).all()
    flat = np.floor(pts[:, 1]).astype(int) * 60 + np.floor(pts[:, 0]).astype(int)
    frac = np.isin(flat, cells).mean()
    assert abs(frac - 0.5) < 5 * math.sqrt(0.25 / n) + 0.01


def test_a_gap_sampler_that_starts_after_the_run_changes_nothing():
    """While its cells are pending the gap sampler spends no random number: a run that ends
    before ``gap_after`` is the run without it, and so are the first ``gap_after``
    iterations of a run that goes on (both stopped there by the iteration budget, against a
    target no run meets)."""
    g = slit_map(100, 70)
    s, e = (5.5, 10.5), (94.5, 90.5)
    base = plan(g, s, e, config=NO_GAPS, stop="initial", seed=3)
    late = plan(g, s, e, config=NO_GAPS.replace(gap_share=0.5, gap_after=10**8), stop="initial",
                seed=3)  # fmt: skip
    assert_same_run(base, late)
    k = base.iterations // 2
    cut = NO_GAPS.replace(max_iterations=k, eps=0.0)  # the straight line at eps 0: never met
    a = plan(g, s, e, config=cut, stop="optimal", reference_length=math.dist(s, e), seed=3)
    b = plan(g, s, e, config=cut.replace(gap_share=0.5, gap_after=k), stop="optimal",
             reference_length=math.dist(s, e), seed=3)  # fmt: skip
    assert a.iterations == b.iterations == k and a.stop_reason == "max_iterations"
    assert_same_run(a, b)
    c = plan(g, s, e, config=cut.replace(max_iterations=k + 200, gap_share=0.5,
             gap_after=k), stop="optimal", reference_length=math.dist(s, e), seed=3)  # fmt: skip
    assert c.tree_size != a.tree_size or c.collision_checks != a.collision_checks  # it drew


def assert_same_run(a, b):
    """The same tree and answer: iterations, nodes, checks, cost, path and trace."""
    for f in ("iterations", "tree_size", "collision_checks", "cost"):
        assert getattr(a, f) == getattr(b, f), f
    np.testing.assert_array_equal(a.path, b.path)
    np.testing.assert_array_equal(a.trace_iterations, b.trace_iterations)
    np.testing.assert_array_equal(a.trace_costs, b.trace_costs)


def test_the_gap_sampler_finds_a_slit_in_fewer_iterations():
    """Through the results: on a one-cell slit, gap draws reach the first solution in fewer
    iterations (median over 7 seeds, at least 3x fewer) and every path is exact-free."""
    g = slit_map(100, 70)
    s, e = (5.5, 10.5), (94.5, 90.5)
    its = {}
    for share in (0.0, 0.2):
        cfg = NO_GAPS.replace(gap_share=share, gap_after=0)
        rs = [plan(g, s, e, config=cfg, stop="initial", seed=k) for k in range(7)]
        assert all(r.success and path_free(g, r.path) for r in rs)
        its[share] = np.median([r.iterations for r in rs])
    assert its[0.2] * 3 <= its[0.0], its


@pytest.mark.parametrize(
    ("field", "value"),
    [
        ("gap_share", -0.1),
        ("gap_share", 1.5),
        ("gap_width", 0),
        ("gap_width", 2.5),
        ("gap_width", 2**40),
        ("gap_after", -1),
        ("gap_after", 2.5),
        ("gap_after", True),
        ("gap_after", 2**63),
    ],
)
def test_bad_gap_settings_are_named(field, value):
    with pytest.raises(PlannerConfigError, match=field):
        PlannerConfig().replace(**{field: value})
