"""Exact any-angle shortest paths against an independent exact brute force.

The brute force uses every grid vertex (not only convex corners) plus start and goal as
nodes, a pure-Python visibility test in exact rational arithmetic (``Fraction``), and
Dijkstra; it shares no code with :mod:`vnrrt.search.anyangle`.
"""

import heapq
import itertools
import math
from fractions import Fraction

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from tests.conftest import random_grid
from vnrrt.grid import GridError
from vnrrt.planners import reference_length, segment_free, taut_length
from vnrrt.search import (
    NoPathError,
    any_angle_length,
    any_angle_path,
    astar,
    convex_corners,
    segment_visible,
)
from vnrrt.search.anyangle import _into

# --- independent exact reference -------------------------------------------------------


def blocked(grid, x: int, y: int) -> bool:
    h, w = grid.shape
    return not (0 <= x < w and 0 <= y < h) or bool(grid[y, x])


def is_pinch(grid, k: int, j: int) -> bool:
    a, b = blocked(grid, k - 1, j - 1), blocked(grid, k, j - 1)
    c, d = blocked(grid, k - 1, j), blocked(grid, k, j)
    return (a and d and not b and not c) or (b and c and not a and not d)


def exact_visible(grid, p, q) -> bool:
    """The visibility rule in exact arithmetic: cut P->Q at every grid-line crossing; each
    piece's midpoint must be inside a free cell, or on an edge with a free side when the
    piece lies on a grid line; no pinch vertex strictly inside the segment."""
    (x0, y0), (x1, y1) = [(Fraction(a), Fraction(b)) for a, b in (p, q)]
    dx, dy = x1 - x0, y1 - y0
    if dx == dy == 0:
        return True  # a point (documented convention)
    ts = {Fraction(0), Fraction(1)}
    for z0, dz in ((x0, dx), (y0, dy)):
        if dz:
            lo, hi = sorted((z0, z0 + dz))
            ts.update((k - z0) / dz for k in range(math.ceil(lo), math.floor(hi) + 1))
    ts = sorted(ts)
    for t in ts[1:-1]:
        x, y = x0 + t * dx, y0 + t * dy
        if x.denominator == 1 and y.denominator == 1 and is_pinch(grid, int(x), int(y)):
            return False
    for ta, tb in itertools.pairwise(ts):
        tm = (ta + tb) / 2
        mx, my = x0 + tm * dx, y0 + tm * dy
        if mx.denominator == 1:  # on a vertical grid line: the edge needs a free side
            k, j = int(mx), math.floor(my)
            if blocked(grid, k - 1, j) and blocked(grid, k, j):
                return False
        elif my.denominator == 1:
            k, j = math.floor(mx), int(my)
            if blocked(grid, k, j - 1) and blocked(grid, k, j):
                return False
        elif blocked(grid, math.floor(mx), math.floor(my)):
            return False
    return True


def brute_length(grid, start, goal) -> float:
    """Dijkstra over all grid vertices + start + goal with exact visibility (lazily
    evaluated: an edge is tested only when it would improve a tentative distance and the
    goal's).

    Pinch vertices are left out: a path bending there would cross from one free cell to
    the diagonally opposite one through the point where the two obstacles meet."""
    h, w = grid.shape
    nodes = [tuple(start), tuple(goal)]
    nodes += [(x, y) for y in range(h + 1) for x in range(w + 1) if not is_pinch(grid, x, y)]
    dist = [math.inf] * len(nodes)
    done = [False] * len(nodes)
    dist[0] = 0.0
    heap = [(0.0, 0)]
    while heap:
        d, u = heapq.heappop(heap)
        if done[u]:
            continue
        done[u] = True
        if u == 1:
            return d
        for v, pv in enumerate(nodes):
            nd = d + math.dist(nodes[u], pv)
            if done[v] or nd >= dist[v] - 1e-12 or nd + math.dist(pv, goal) >= dist[1]:
                continue  # no improvement, or cannot lead to a shorter path to the goal
            if exact_visible(grid, nodes[u], pv):
                dist[v] = nd
                heapq.heappush(heap, (nd, v))
    return math.inf


def corner_quadrants(grid) -> dict[tuple[int, int], tuple[int, int]]:
    """Convex corners (exactly one blocked cell; outside counts) -> quadrant of that cell."""
    pad = np.pad(np.asarray(grid) != 0, 1, constant_values=True)
    a, b, c, d = pad[:-1, :-1], pad[:-1, 1:], pad[1:, :-1], pad[1:, 1:]  # around (k, j)
    one = a.astype(int) + b + c + d == 1
    sx, sy = np.where(b | d, 1, -1), np.where(c | d, 1, -1)
    return {(k, j): (int(sx[j, k]), int(sy[j, k])) for j, k in np.argwhere(one)}


def shifted_path_free(grid, pts, eps=1e-6) -> bool:
    """Replace every convex corner touched by the path (turning points and corners the
    segments graze) by the corner moved ``eps`` diagonally away from its blocked cell;
    the resulting polyline must be free under the planner's conservative test."""
    quads = corner_quadrants(grid)
    corners = np.array(list(quads), dtype=np.int64).reshape(-1, 2)
    for p, q in itertools.pairwise(np.asarray(pts)):
        p2, q2 = np.round(2 * p).astype(np.int64), np.round(2 * q).astype(np.int64)
        d, c = q2 - p2, 2 * corners - p2
        on = (d[0] * c[:, 1] - d[1] * c[:, 0] == 0) & (c @ d >= 0) & (c @ d <= d @ d)
        touched = sorted(map(tuple, corners[on]), key=lambda c: (np.array(c) * 2 - p2) @ d)
        poly = [tuple(c - eps * np.array(quads[c])) for c in touched]
        if tuple(p) not in quads:
            poly.insert(0, tuple(p))
        if tuple(q) not in quads:
            poly.append(tuple(q))
        for a, b in itertools.pairwise(poly):
            if not segment_free(grid, a[0], a[1], b[0], b[1]):
                return False
    return True


def check_path(grid, pts, length, start, goal):
    pts = np.asarray(pts)
    assert pts.dtype == np.float64 and pts.ndim == 2 and pts.shape[1] == 2
    assert np.array_equal(pts[0], start) and np.array_equal(pts[-1], goal)
    assert length == pytest.approx(np.hypot(*np.diff(pts, axis=0).T).sum(), abs=1e-9)
    quads = corner_quadrants(grid)
    assert all(tuple(p) in quads for p in pts[1:-1]), "turning point not a convex corner"
    assert {tuple(c) for c in convex_corners(grid).tolist()} == set(quads)
    for a, b in itertools.pairwise(pts):
        assert segment_visible(grid, a[0], a[1], b[0], b[1])
    assert shifted_path_free(grid, pts)


def free_centres(grid):
    return [(x + 0.5, y + 0.5) for y, x in np.argwhere(grid == 0)]


# --- against the brute force ------------------------------------------------------------

small_maps = st.tuples(
    st.integers(0, 10**6), st.integers(6, 12), st.integers(6, 12), st.floats(0.2, 0.4)
)


@settings(max_examples=50)
@given(small_maps, st.data())
def test_length_equals_brute_force(params, data):
    seed, h, w, density = params
    grid = random_grid(seed, h, w, density)
    free = free_centres(grid)
    if len(free) < 2:
        return
    s, g = data.draw(st.lists(st.sampled_from(free), min_size=2, max_size=2, unique=True))
    ref = brute_length(grid, s, g)
    if not math.isfinite(ref):
        with pytest.raises(NoPathError):
            any_angle_path(grid, s, g)
        return
    pts, length = any_angle_path(grid, s, g)
    assert length == pytest.approx(ref, abs=1e-9)
    check_path(grid, pts, length, s, g)
    assert math.dist(s, g) - 1e-9 <= length <= taut_length(grid, s, g) + 1e-9


@settings(max_examples=100)
@given(st.integers(0, 10**6), st.integers(2, 14), st.integers(2, 14), st.floats(0.0, 0.6))
def test_segment_visible_equals_exact_rule(seed, h, w, density):
    """Random segments between cell centres, grid vertices and edge midpoints."""
    grid = random_grid(seed, h, w, density)
    rng = np.random.default_rng(seed)
    pts = rng.integers(0, 2 * np.array([w, h]) + 1, size=(40, 2)) / 2
    for p, q in zip(pts[:20], pts[20:]):
        assert segment_visible(grid, *p, *q) == exact_visible(grid, p, q), (p, q)


@pytest.mark.parametrize("sx", [-1, 1])
@pytest.mark.parametrize("sy", [-1, 1])
def test_tangent_rule(sx, sy):
    """The line through a corner with direction d enters the blocked cell's interior iff a
    point just along +d or -d lies inside that open unit cell."""
    cell_lo = np.array([min(sx, 0), min(sy, 0)], dtype=float)  # the blocked cell's corner
    for dx, dy in itertools.product(range(-3, 4), repeat=2):
        if dx == dy == 0:
            continue
        d = np.array([dx, dy]) / math.hypot(dx, dy) * 1e-3
        inside = [bool(np.all((e > cell_lo) & (e < cell_lo + 1))) for e in (d, -d)]
        assert _into(float(dx), float(dy), sx, sy) == any(inside), (dx, dy, sx, sy)


# --- hand-made cases ----------------------------------------------------------------------


def test_empty_map_is_straight_line():
    g = np.zeros((30, 40), np.uint8)
    s, e = (0.5, 0.5), (39.5, 17.5)
    pts, length = any_angle_path(g, s, e)
    assert pts.shape == (2, 2) and length == pytest.approx(math.dist(s, e), abs=1e-12)
    assert len(convex_corners(g)) == 0


def test_one_block_two_segments():
    g = np.zeros((20, 20), np.uint8)
    g[3:15, 5:10] = 1  # block [5, 10] x [3, 15]
    s, e = (2.5, 10.5), (12.5, 18.5)
    pts, length = any_angle_path(g, s, e)
    assert pts.tolist() == [[2.5, 10.5], [5.0, 15.0], [12.5, 18.5]]
    assert length == pytest.approx(math.hypot(2.5, 4.5) + math.hypot(7.5, 3.5), abs=1e-12)
    check_path(g, pts, length, s, e)


def test_path_along_an_edge():
    """Start and goal level with the block's top edge: the path runs along it."""
    g = np.zeros((10, 12), np.uint8)
    g[4:8, 3:9] = 1  # block [3, 9] x [4, 8]
    s, e = (1.5, 2.5), (10.5, 2.5)
    assert any_angle_length(g, s, e) == pytest.approx(9.0)
    s, e = (1.5, 5.5), (10.5, 5.5)  # around the top: (3, 4) -> (9, 4)
    pts, length = any_angle_path(g, s, e)
    assert pts.tolist() == [[1.5, 5.5], [3.0, 4.0], [9.0, 4.0], [10.5, 5.5]]
    assert length == pytest.approx(6 + 2 * math.hypot(1.5, 1.5))
    check_path(g, pts, length, s, e)


def test_pinch_vertex_is_not_passable():
    g = np.zeros((4, 4), np.uint8)
    g[1, 1] = g[2, 2] = 1  # cells (1, 1) and (2, 2) touch at vertex (2, 2)
    s, e = (2.5, 1.5), (1.5, 2.5)  # the two free cells meeting at the pinch
    assert not segment_visible(g, *s, *e)
    pts, length = any_angle_path(g, s, e)
    assert length == pytest.approx(2 + math.sqrt(2))  # around either block: corner, 2 edges
    assert [2.0, 2.0] not in pts.tolist()
    check_path(g, pts, length, s, e)


def test_convex_corner_is_passable():
    """Same cells but one more free: the vertex is a convex corner and may be touched."""
    g = np.zeros((4, 4), np.uint8)
    g[1, 1] = 1
    s, e = (1.5, 2.5), (3.0, 1.0)
    assert segment_visible(g, 2.5, 1.5, 1.5, 2.5)
    assert any_angle_length(g, (2.5, 1.5), (1.5, 2.5)) == pytest.approx(math.sqrt(2))
    assert segment_visible(g, 1.0, 3.0, *e)  # through corner (2, 2) diagonally
    assert any_angle_length(g, s, (3.5, 0.5)) == pytest.approx(math.dist(s, (3.5, 0.5)))


def test_corridors_one_cell_wide():
    g = np.ones((5, 10), np.uint8)
    g[2] = 0  # a horizontal corridor between blocked rows
    pts, length = any_angle_path(g, (0.5, 2.5), (9.5, 2.5))
    assert pts.shape == (2, 2) and length == pytest.approx(9.0)
    g = np.zeros((10, 10), np.uint8)
    g[:, 5] = 1
    g[3, 5] = 0  # a wall x in [5, 6] with a one-cell gap at y in [3, 4]
    s, e = (1.5, 8.5), (8.5, 8.5)
    pts, length = any_angle_path(g, s, e)
    assert pts.tolist() == [[1.5, 8.5], [5.0, 4.0], [6.0, 4.0], [8.5, 8.5]]
    assert length == pytest.approx(math.hypot(3.5, 4.5) + 1 + math.hypot(2.5, 4.5))
    check_path(g, pts, length, s, e)


def test_map_border_is_blocked_but_touchable():
    g = np.zeros((6, 8), np.uint8)
    g[1:, 3] = 1  # a wall from the bottom border up to y = 1
    s, e = (1.5, 4.5), (5.5, 4.5)
    pts, length = any_angle_path(g, s, e)
    assert pts.tolist() == [[1.5, 4.5], [3.0, 1.0], [4.0, 1.0], [5.5, 4.5]]
    check_path(g, pts, length, s, e)
    g[0, 3] = 1  # closed: the path may not run along the border
    with pytest.raises(NoPathError):
        any_angle_path(g, s, e)
    assert not segment_visible(g, 3.0, 0.0, 4.0, 0.0)
    g[0, 3] = 0
    g[1, 3] = 0  # free cells below the top border: running along it is allowed
    assert segment_visible(g, 2.0, 0.0, 5.0, 0.0)


def test_errors():
    g = np.zeros((8, 8), np.uint8)
    g[:, 4] = 1
    with pytest.raises(NoPathError):
        any_angle_path(g, (1.5, 1.5), (6.5, 6.5))
    with pytest.raises(NoPathError):
        reference_length(g, (1.5, 1.5), (6.5, 6.5), "any_angle")
    with pytest.raises(GridError):
        any_angle_path(g, (4.5, 1.5), (6.5, 6.5))
    with pytest.raises(GridError):
        any_angle_length(g, (1.5, 1.5), (8.5, 6.5))
    with pytest.raises(GridError):
        any_angle_length(g.astype(float), (1.5, 1.5), (2.5, 6.5))


# --- real maps ----------------------------------------------------------------------------


@pytest.fixture(scope="module")
def real_maps():
    from vnrrt.maps.config import DataConfig
    from vnrrt.maps.generate import generate_map, map_rng

    return [generate_map(map_rng(0, i), DataConfig()) for i in range(6)]


def test_real_maps_between_bounds_and_approachable(real_maps):
    for fm in real_maps:
        for sc, gc in zip(fm.starts[:3], fm.goals[:3]):
            s, e = sc + 0.5, gc + 0.5
            pts, length = any_angle_path(fm.grid, s, e)
            check_path(fm.grid, pts, length, s, e)
            assert math.dist(s, e) - 1e-9 <= length <= taut_length(fm.grid, s, e) + 1e-9
            assert length <= astar(fm.grid, sc, gc)[1] + 1e-9


@pytest.mark.parametrize("seed", range(30))
def test_random_maps_between_bounds(seed):
    grid = random_grid(seed, 40, 50, 0.25)
    free = free_centres(grid)
    rng = np.random.default_rng(seed)
    for _ in range(5):
        s, e = (free[i] for i in rng.choice(len(free), 2, replace=False))
        try:
            pts, length = any_angle_path(grid, s, e)
        except NoPathError:
            with pytest.raises(NoPathError):
                taut_length(grid, s, e)
            continue
        assert math.dist(s, e) - 1e-9 <= length <= taut_length(grid, s, e) + 1e-9
        for a, b in itertools.pairwise(pts):
            assert segment_visible(grid, *a, *b)


def test_deterministic(real_maps):
    fm = real_maps[0]
    s, e = fm.starts[0] + 0.5, fm.goals[0] + 0.5
    a, b = any_angle_path(fm.grid, s, e), any_angle_path(fm.grid.copy(), s, e)
    assert np.array_equal(a[0], b[0]) and a[1] == b[1]
    assert any_angle_length(fm.grid, s, e) == a[1]
