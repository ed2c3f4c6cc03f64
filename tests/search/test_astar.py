"""A* and distance fields against an independent shortest-path reference (scipy csgraph)."""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import dijkstra

from vnrrt.grid import GridError
from vnrrt.search import NoPathError, astar, descend, distance_field, move_masks, path_length


def reference_graph(grid: np.ndarray):
    """The 8-connected, no-corner-cutting graph built independently with numpy: node
    ``y * W + x`` for every cell, edges only between free cells."""
    h, w = grid.shape
    free = grid == 0
    rows, cols, costs = [], [], []
    for dx, dy in [(1, 0), (0, 1), (1, 1), (-1, 1)]:
        y0, y1 = 0, h - dy
        x0, x1 = max(0, -dx), w - max(0, dx)
        ys, xs = np.mgrid[y0:y1, x0:x1]
        ok = free[ys, xs] & free[ys + dy, xs + dx]
        if dx and dy:  # both orthogonal neighbours must be free
            ok &= free[ys, xs + dx] & free[ys + dy, xs]
        a, b = (ys * w + xs)[ok], ((ys + dy) * w + xs + dx)[ok]
        rows += [a, b]
        cols += [b, a]
        costs += [np.full(len(a), math.hypot(dx, dy))] * 2
    n = h * w
    return coo_matrix((np.concatenate(costs), (np.concatenate(rows), np.concatenate(cols))), (n, n))


def assert_valid_path(grid, path, start, goal):
    path = np.asarray(path)
    assert path[0].tolist() == list(start) and path[-1].tolist() == list(goal)
    assert np.all(grid[path[:, 1], path[:, 0]] == 0), "path leaves free space"
    steps = np.diff(path, axis=0)
    assert np.all(np.abs(steps).max(axis=1) == 1), "path is not 8-connected"
    for (x, y), (dx, dy) in zip(path[:-1], steps):
        if dx and dy:
            assert grid[y, x + dx] == 0 and grid[y + dy, x] == 0, "diagonal cuts a corner"


grids = st.tuples(
    st.integers(0, 10**6), st.integers(5, 30), st.integers(5, 30), st.floats(0.0, 0.45)
)


@given(grids, st.data())
def test_astar_length_equals_reference(params, data):
    seed, h, w, density = params
    rng = np.random.default_rng(seed)
    grid = (rng.random((h, w)) < density).astype(np.uint8)
    free = np.argwhere(grid == 0)
    if len(free) < 2:
        return
    i, j = data.draw(st.lists(st.integers(0, len(free) - 1), min_size=2, max_size=2))
    start, goal = (int(free[i][1]), int(free[i][0])), (int(free[j][1]), int(free[j][0]))
    ref = dijkstra(reference_graph(grid), indices=start[1] * w + start[0])[goal[1] * w + goal[0]]
    if not np.isfinite(ref):
        with pytest.raises(NoPathError):
            astar(grid, start, goal)
        return
    path, length = astar(grid, start, goal)
    assert length == pytest.approx(ref, abs=1e-9)
    assert path_length(path) == pytest.approx(length, abs=1e-9)
    assert_valid_path(grid, path, start, goal)


@given(st.integers(0, 10**6), st.floats(0.0, 0.4))
def test_distance_field_equals_reference_and_descends_optimally(seed, density):
    rng = np.random.default_rng(seed)
    grid = (rng.random((20, 26)) < density).astype(np.uint8)
    free = np.argwhere(grid == 0)
    if len(free) < 2:
        return
    gy, gx = free[0]
    dist = distance_field(move_masks(grid), (gx, gy))
    ref = dijkstra(reference_graph(grid), indices=gy * 26 + gx).reshape(20, 26)
    np.testing.assert_allclose(dist, ref, atol=1e-9)
    for sy, sx in free[1:6]:
        if np.isfinite(ref[sy, sx]):
            path = np.cumsum(
                np.vstack([[sx, sy], _moves(descend(move_masks(grid), dist, (sx, sy), (gx, gy)))]),
                axis=0,
            )
            assert path_length(path) == pytest.approx(ref[sy, sx], abs=1e-9)
            assert_valid_path(grid, path, (sx, sy), (gx, gy))


def _moves(codes):
    from vnrrt.grid import MOVES

    return MOVES[np.asarray(codes, dtype=np.int64)].reshape(-1, 2)


def test_distance_field_with_targets_is_exact_on_targets():
    rng = np.random.default_rng(3)
    grid = (rng.random((60, 60)) < 0.25).astype(np.uint8)
    free = np.argwhere(grid == 0)
    goal = free[0][::-1]
    targets = free[[5, 17, 40]][:, ::-1]
    full = distance_field(move_masks(grid), goal)
    early = distance_field(move_masks(grid), goal, targets)
    for x, y in targets:
        assert early[y, x] == full[y, x]
    assert np.isinf(early).sum() >= np.isinf(full).sum()


def test_no_corner_cutting_and_known_length():
    grid = np.zeros((3, 3), np.uint8)
    grid[0, 1] = 1  # cell (x=1, y=0): the diagonal (0,0) -> (1,1) would cut its corner
    path, length = astar(grid, (0, 0), (1, 1))
    assert length == pytest.approx(2.0)  # two straight moves instead of sqrt(2)
    assert_valid_path(grid, path, (0, 0), (1, 1))
    open_path, open_len = astar(np.zeros((3, 3), np.uint8), (0, 0), (2, 2))
    assert open_len == pytest.approx(2 * math.sqrt(2)) and len(open_path) == 3


def test_straight_line_is_a_straight_path():
    path, length = astar(np.zeros((10, 40), np.uint8), (2, 5), (37, 5))
    assert length == 35 and np.all(path[:, 1] == 5)


def test_bad_input_errors_name_the_problem():
    grid = np.zeros((10, 10), np.uint8)
    grid[:, 5] = 1
    with pytest.raises(NoPathError, match="no path"):
        astar(grid, (0, 0), (9, 9))
    with pytest.raises(GridError, match="start .* obstacle"):
        astar(grid, (5, 3), (9, 9))
    with pytest.raises(GridError, match="goal .* outside"):
        astar(grid, (0, 0), (10, 3))
    with pytest.raises(GridError, match="2-D"):
        astar(np.zeros((4, 4, 1), np.uint8), (0, 0), (1, 1))
    with pytest.raises(GridError, match="dtype"):
        astar(grid.astype(float), (0, 0), (1, 1))


def detour_grid(rng: np.random.Generator, h: int, w: int) -> np.ndarray:
    """Walls across the map with one or two gaps each, plus clutter: the greedy direction
    to the goal is wrong and the optimal path detours, so the heuristic decides what A*
    expands (random sparse grids rarely show a bad heuristic)."""
    grid = (rng.random((h, w)) < 0.08).astype(np.uint8)
    for _ in range(int(rng.integers(2, 5))):
        if rng.random() < 0.5:
            x = int(rng.integers(2, w - 2))
            grid[:, x] = 1
            for _ in range(int(rng.integers(1, 3))):
                y = int(rng.integers(0, h - 2))
                grid[y : y + 2, x] = 0
        else:
            y = int(rng.integers(2, h - 2))
            grid[y, :] = 1
            for _ in range(int(rng.integers(1, 3))):
                x = int(rng.integers(0, w - 2))
                grid[y, x : x + 2] = 0
    return grid


@settings(max_examples=150)
@given(st.integers(0, 10**6))
def test_astar_is_optimal_where_the_heuristic_matters(seed):
    """Mutations of vnrrt.search.astar this test must catch (each checked once by hand and
    by tests/search/test_astar_mutations.py, slow):

    * an overestimating heuristic, ``max + min`` instead of ``max + (sqrt 2 - 1) min``;
    * diagonal moves costing 1 instead of sqrt 2;
    * corner cutting allowed (the orthogonal-neighbour check removed);
    * improvements refused unless better by more than 1 px.
    """
    rng = np.random.default_rng(seed)
    h, w = int(rng.integers(20, 60)), int(rng.integers(20, 60))
    grid = detour_grid(rng, h, w)
    free = np.argwhere(grid == 0)
    for _ in range(3):
        (sy, sx), (gy, gx) = free[rng.choice(len(free), 2, replace=False)]
        ref = dijkstra(reference_graph(grid), indices=sy * w + sx)[gy * w + gx]
        if not np.isfinite(ref):
            continue
        path, length = astar(grid, (int(sx), int(sy)), (int(gx), int(gy)))
        assert length == pytest.approx(ref, abs=1e-9)
        assert path_length(path) == pytest.approx(ref, abs=1e-9)
        assert_valid_path(grid, path, (sx, sy), (gx, gy))


def turns(path) -> int:
    """Direction changes along a cell path (T+1, 2)."""
    steps = np.diff(np.asarray(path), axis=0)
    return int(np.any(steps[1:] != steps[:-1], axis=1).sum())


def distance_to_segment(points, a, b) -> np.ndarray:
    """Distances (N,) of cell centres ``points`` (N, 2) to the segment between centres a, b."""
    p, a, b = np.asarray(points) + 0.5, np.asarray(a) + 0.5, np.asarray(b) + 0.5
    t = np.clip(((p - a) @ (b - a)) / ((b - a) @ (b - a)), 0, 1)
    return np.linalg.norm(p - (a + t[:, None] * (b - a)), axis=1)


TIE_OPTIONS = [("turns", 0.0), ("line", 0.0), ("line", 3.0), ("exact", 0.0), ("exact", 3.0)]


@settings(max_examples=30, deadline=None)
@given(st.integers(0, 10**6), st.floats(0.0, 0.35))
def test_every_tie_break_gives_an_equally_short_valid_path(seed, density):
    rng = np.random.default_rng(seed)
    grid = (rng.random((24, 24)) < density).astype(np.uint8)
    free = np.argwhere(grid == 0)
    if len(free) < 2:
        return
    (sy, sx), (gy, gx) = free[rng.choice(len(free), 2, replace=False)]
    try:
        _, want = astar(grid, (sx, sy), (gx, gy))
    except NoPathError:
        return
    for tie_break, tol in TIE_OPTIONS:
        path, length = astar(grid, (sx, sy), (gx, gy), tie_break, tol)
        assert length == want and path_length(path) == pytest.approx(want, abs=1e-9)
        assert_valid_path(grid, path, (sx, sy), (gx, gy))


def test_tie_breaks_have_their_documented_shape_in_free_space():
    """From (2, 3) to (33, 14) in an empty grid every octile path of 11 diagonal and 20
    straight moves is optimal: ``turns`` takes one or two bends (A* settles only part of
    the field, so a straight run can end early); ``line`` (and ``exact``, whose
    optimum is the same segment) stay within a cell's half-diagonal of the straight line;
    a tolerance lets them run straight longer, so fewer turns, never farther than it plus
    a cell from the line."""
    grid, s, g = np.zeros((20, 40), np.uint8), (2, 3), (33, 14)
    paths = {opt: astar(grid, s, g, *opt)[0] for opt in TIE_OPTIONS}
    assert 1 <= turns(paths["turns", 0.0]) <= 2
    for tie_break in ("line", "exact"):
        hug = paths[tie_break, 0.0]
        assert distance_to_segment(hug, s, g).max() <= math.sqrt(2) / 2 + 1e-9
        loose = paths[tie_break, 3.0]
        assert distance_to_segment(loose, s, g).max() <= 3.0 + math.sqrt(2) + 1e-9
        assert turns(paths["turns", 0.0]) <= turns(loose) < turns(hug)


def test_line_tie_break_bends_at_the_obstacle_corner():
    """A wall between start and goal: the exact optimum bends at the wall's end corner; the
    ``line`` and ``exact`` label paths pass within 1.5 px of that corner cell, ``turns``
    (an L-shaped octile path) need not."""
    grid = np.zeros((30, 30), np.uint8)
    grid[5:30, 15] = 1  # a wall x = 15 from y = 5 down; its free end corner near (15, 4)
    s, g = (3, 25), (27, 25)
    corner = np.array([15.5, 4.5])  # the corner region above the wall
    for tie_break in ("line", "exact"):
        path = astar(grid, s, g, tie_break)[0] + 0.5
        assert np.linalg.norm(path - corner, axis=1).min() <= 1.5
