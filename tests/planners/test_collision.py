"""Exact segment-versus-grid test against independent references (closed obstacle squares)."""

import numpy as np
import pytest

from vnrrt.planners import path_free, point_free, segment_free
from vnrrt.planners.collision import MARGIN
from vnrrt.planners.rrt_star import straight_cost


def touches_box(p0, p1, lo, hi) -> bool:
    """Liang-Barsky: does segment p0-p1 meet the closed box [lo, hi] (2-vectors)?"""
    t0, t1 = 0.0, 1.0
    d = p1 - p0
    for a in range(2):
        if d[a] == 0.0:
            if not lo[a] <= p0[a] <= hi[a]:
                return False
            continue
        ta, tb = sorted(((lo[a] - p0[a]) / d[a], (hi[a] - p0[a]) / d[a]))
        t0, t1 = max(t0, ta), min(t1, tb)
        if t0 > t1:
            return False
    return True


def reference_free(grid, p0, p1) -> bool:
    """Brute force: no closed obstacle square (and no map border) touched."""
    h, w = grid.shape
    pts = np.array([p0, p1])
    if pts[:, 0].min() <= 0 or pts[:, 1].min() <= 0 or pts[:, 0].max() >= w:
        return False
    if pts[:, 1].max() >= h:
        return False
    for y, x in np.argwhere(grid):
        if touches_box(np.asarray(p0), np.asarray(p1), np.array([x, y]), np.array([x + 1, y + 1])):
            return False
    return True


def sampled_free(grid, p0, p1, step=0.005) -> bool:
    """Finely sampled point checks (open cells): weaker than the exact rule."""
    n = int(np.ceil(np.hypot(*(np.subtract(p1, p0))) / step)) + 1
    t = np.linspace(0.0, 1.0, n)[:, None]
    cells = np.floor(np.asarray(p0) + t * np.subtract(p1, p0)).astype(int)
    return not grid[cells[:, 1], cells[:, 0]].any()


@pytest.fixture(scope="module")
def grid():
    rng = np.random.default_rng(7)
    return (rng.random((12, 14)) < 0.25).astype(np.uint8)


def test_corner_touch_counts_both_diagonal_cells():
    g = np.zeros((4, 4), np.uint8)
    g[1, 2] = 1  # cell (2, 1); its corner (2, 2) lies on the diagonal below
    assert not segment_free(g, 1.5, 1.5, 2.5, 2.5)  # passes exactly through corner (2, 2)
    assert not segment_free(g, 2.5, 2.5, 1.5, 1.5)  # same segment reversed
    assert segment_free(g, 1.5, 1.6, 2.4, 2.5)  # misses the corner by 0.07 px
    g = np.zeros((4, 4), np.uint8)
    g[2, 1] = 1  # the other diagonal neighbour, cell (1, 2)
    assert not segment_free(g, 1.5, 1.5, 2.5, 2.5)


def test_edges_and_border_are_closed():
    g = np.zeros((5, 5), np.uint8)
    g[:, 1] = 1  # column x = 1 covers [1, 2]
    assert not segment_free(g, 2.0, 0.5, 2.0, 4.5)  # runs along its right edge
    assert segment_free(g, 2.0 + 1e-6, 0.5, 2.0 + 1e-6, 4.5)
    assert not segment_free(g, 3.5, 0.0, 3.5, 2.0)  # touches the top border y = 0
    assert not point_free(g, (2.0, 3.0)) and point_free(g, (2.5, 3.0))


@pytest.mark.parametrize("lattice", [True, False])
def test_matches_brute_force_reference(grid, lattice):
    rng = np.random.default_rng(11 + lattice)
    h, w = grid.shape
    agree, blocked = 0, 0
    for _ in range(1500):
        p = rng.uniform(0.2, [w - 0.2, h - 0.2, w - 0.2, h - 0.2])
        if lattice:  # endpoints on the half-pixel lattice hit corners and edges exactly
            p = np.clip(np.round(p * 2) / 2, 0.5, [w - 0.5, h - 0.5, w - 0.5, h - 0.5])
        got = segment_free(grid, *p)
        assert got == reference_free(grid, p[:2], p[2:]), p
        agree += 1
        blocked += not got
    assert agree == 1500 and 200 < blocked < 1400  # both outcomes well represented


def test_never_weaker_than_sampling(grid):
    rng = np.random.default_rng(3)
    h, w = grid.shape
    for _ in range(500):
        p = rng.uniform(0.1, [w - 0.1, h - 0.1, w - 0.1, h - 0.1])
        if segment_free(grid, *p):
            assert sampled_free(grid, p[:2], p[2:])


def test_path_free_checks_every_segment():
    g = np.zeros((6, 6), np.uint8)
    g[3, 3] = 1
    ok = np.array([[0.5, 0.5], [5.5, 0.5], [5.5, 5.5]])
    bad = np.array([[0.5, 0.5], [0.5, 5.5], [5.5, 0.5]])  # last leg crosses (3, 3)'s corner
    assert path_free(g, ok) and not path_free(g, bad)


@pytest.mark.parametrize("lattice", [False, True])
def test_a_querys_compiled_checks_match_the_brute_force_reference(grid, lattice):
    """A query's compiled checks: an endpoint's zero-length segment is not free when it
    touches an obstacle or the border; straight_cost is the start-goal distance when the
    segment is free and -1 when it is blocked; checked against :func:`reference_free`."""
    rng = np.random.default_rng(29 + lattice)
    h, w = grid.shape
    seen = set()
    for _ in range(1500):
        p = rng.uniform(0.2, [w - 0.2, h - 0.2, w - 0.2, h - 0.2])
        if lattice:  # endpoints on cell edges and corners
            p = np.clip(np.round(p * 2) / 2, 0.5, [w - 0.5, h - 0.5, w - 0.5, h - 0.5])
        a, b = p[:2], p[2:]
        if not (reference_free(grid, a, a) and reference_free(grid, b, b)):
            want = "bad"
        elif reference_free(grid, a, b):
            want = float(np.hypot(*(b - a)))
        else:
            want = -1.0
        ends_free = segment_free(grid, *a, *a) and segment_free(grid, *b, *b)
        assert ends_free is (want != "bad"), p
        if want != "bad":
            assert straight_cost(grid, *p) == pytest.approx(want, abs=1e-12), p
        seen.add(want if want == "bad" else "blocked" if want < 0 else "free")
    assert seen == {"bad", "blocked", "free"}


@pytest.mark.parametrize("shape", [(7, 40), (40, 7), (23, 31)])
def test_shallow_steep_and_axis_parallel_segments_match_the_reference(shape):
    """The column walk's one-or-two-cell step (a shallow segment) and its loop (a steep one)
    agree with :func:`reference_free` on maps that are not square, for segments of every
    slope: random, on the half-pixel lattice (edges and corners hit exactly), horizontal and
    vertical."""
    rng = np.random.default_rng(sum(shape))
    h, w = shape
    grid = (rng.random(shape) < 0.06).astype(np.uint8)
    hi = [w - 0.2, h - 0.2, w - 0.2, h - 0.2]
    seen = {True: 0, False: 0}
    for i in range(1200):
        p = rng.uniform(0.2, hi)
        if i % 4 == 1:
            p = np.clip(np.round(p * 2) / 2, 0.5, np.subtract(hi, 0.3))
        elif i % 4 == 2:
            p[3] = p[1]  # horizontal
        elif i % 4 == 3:
            p[2] = p[0]  # vertical
        got = segment_free(grid, *p)
        assert got == reference_free(grid, p[:2], p[2:]), p
        seen[got] += 1
    assert min(seen.values()) > 100


def test_coordinates_outside_the_map_or_not_finite_are_never_free():
    """Off-map, infinite and NaN coordinates give False: a segment to x = 1e300 was reported
    free before (the column count overflowed an int64 and the walk tested no column)."""
    g = np.zeros((50, 60), np.uint8)
    assert segment_free(g, 1.5, 20.0, 58.5, 30.0)
    bad = [1e300, -1e300, 1e20, np.inf, -np.inf, np.nan, 60.0, -0.5, 0.0]  # 60: x = W, y > H
    for v in bad:
        for k in range(4):
            p = [1.5, 20.0, 58.5, 30.0]
            p[k] = v
            assert not segment_free(g, *p), p
    for v in (np.inf, np.nan):  # a vertical segment with one end not finite
        assert not segment_free(g, 3.5, 20.0, 3.5, v) and not segment_free(g, 3.5, v, 3.5, 20.0)


def column_walk(grid, x0, y0, x1, y1) -> bool:
    """The column walk written plainly (plain Python floats, the same operations in the
    same order as the module docstring's rule): every column's clamped x extent, its y
    extent, the rows in it widened by the margin, every cell tested."""
    h, w = grid.shape
    if x0 > x1:
        x0, y0, x1, y1 = x1, y1, x0, y0
    if not all(np.isfinite((x0, y0, x1, y1))):
        return False
    dx = x1 - x0
    slope = (y1 - y0) / dx if dx > 0.0 else 0.0
    c_lo, c_hi = int(np.floor(x0 - MARGIN)), int(np.floor(x1 + MARGIN))
    if c_lo < 0 or c_hi >= w:
        return False
    for cx in range(c_lo, c_hi + 1):
        xa, xb = min(max(x0, float(cx)), x1), max(min(x1, float(cx + 1)), x0)
        ya, yb = (y0 + (xa - x0) * slope, y0 + (xb - x0) * slope) if dx > 0.0 else (y0, y1)
        r_lo, r_hi = int(np.floor(min(ya, yb) - MARGIN)), int(np.floor(max(ya, yb) + MARGIN))
        if r_lo < 0 or r_hi >= h or grid[r_lo : r_hi + 1, cx].any():
            return False
    return True


@pytest.mark.parametrize("shape", [(9, 30), (30, 9), (17, 17)])
def test_segments_within_the_margin_of_edges_match_the_plain_column_walk(shape):
    """At the rounding margin's scale (endpoints on integer and half-pixel coordinates, then
    moved by 0, +-0.5, +-1 or +-2 margins), where the exact reference's closed squares and
    the margin differ by design, the compiled walk answers as :func:`column_walk` does."""
    rng = np.random.default_rng(sum(shape) + 1)
    h, w = shape
    grid = (rng.random(shape) < 0.1).astype(np.uint8)
    offsets = np.array([0.0, 5e-10, -5e-10, 1e-9, -1e-9, 2e-9, -2e-9])
    seen = {True: 0, False: 0}
    for i in range(3000):
        p = np.round(rng.uniform(0.0, [w, h, w, h]) * (1 + i % 2)) / (1 + i % 2)
        p = p + rng.choice(offsets, 4)
        if i % 5 == 3:
            p[2] = p[0]  # vertical
        elif i % 5 == 4:
            p[3] = p[1]  # horizontal
        got = segment_free(grid, *p)
        assert got == column_walk(grid, *(float(v) for v in p)), p
        seen[got] += 1
    assert min(seen.values()) > 200


@pytest.mark.parametrize("dtype", [np.bool_, np.int64, np.float32, np.float64])
def test_any_grid_dtype_gives_the_uint8_answers(grid, dtype):
    """A grid of another dtype (nonzero = obstacle) answers as the uint8 one does."""
    rng = np.random.default_rng(5)
    h, w = grid.shape
    other = grid.astype(dtype)
    for _ in range(300):
        p = rng.uniform(0.2, [w - 0.2, h - 0.2, w - 0.2, h - 0.2])
        assert segment_free(other, *p) == segment_free(grid, *p), p
    path = rng.uniform(0.2, [w - 0.2, h - 0.2], (6, 2))
    assert path_free(other, path) == path_free(grid, path)
