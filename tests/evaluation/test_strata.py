"""Turning-point strata against hand-made maps whose exact optimum turns 0, 1 and 3 times
(the corners derived by hand from each map's geometry), and the mix of a trial table."""

import numpy as np
import pandas as pd
import pytest

from vnrrt.evaluation.strata import (
    assign,
    check_bounds,
    mix,
    stratum_names,
    stratum_of,
    turning_points,
)
from vnrrt.search import any_angle_path

BOUNDS = [0, 1, 3]


def open_map():
    """No obstacle: the goal is in sight, the optimum is the segment."""
    return np.zeros((20, 20), np.uint8), (2.5, 2.5), (17.5, 15.5), []


def one_wall():
    """A wall hanging from the top (x in [15, 16), y in [0, 20)); start below-left, goal
    up-right: the segment from the start to the wall's lower right corner (16, 20) passes
    under the wall (y = 20.6 at x = 15), so that corner is the only turn."""
    grid = np.zeros((30, 30), np.uint8)
    grid[0:20, 15] = 1
    return grid, (2.5, 28.5), (28.5, 2.5), [(16.0, 20.0)]


def block_and_wall():
    """A block (x in [6, 10), y in [20, 30)) before a wall standing on the floor (x in
    [19, 21), y in [10, 30)): over the block's top left corner (6, 20), over both top corners
    of the wall (19, 10), (21, 10), then down to the goal: 3 turns (slopes -2.4, -0.77, 0,
    1.1 increase: the polyline is convex, each corner is needed)."""
    grid = np.zeros((30, 40), np.uint8)
    grid[20:30, 6:10] = 1
    grid[10:30, 19:21] = 1
    return grid, (2.5, 28.5), (37.5, 28.5), [(6.0, 20.0), (19.0, 10.0), (21.0, 10.0)]


@pytest.mark.parametrize(
    ("make", "turns", "stratum"),
    [(open_map, 0, "line of sight"), (one_wall, 1, "1-2 turns"), (block_and_wall, 3, "3+ turns")],
)
def test_the_stratum_of_a_hand_made_map(make, turns, stratum):
    grid, start, goal, corners = make()
    points, _ = any_angle_path(grid, start, goal)
    assert turning_points(points) == turns
    np.testing.assert_allclose(points[1:-1], np.array(corners).reshape(-1, 2))
    assert stratum_of(turning_points(points), BOUNDS) == stratum


def test_the_names_and_bounds_of_strata():
    assert stratum_names([0, 1, 3]) == ["line of sight", "1-2 turns", "3+ turns"]
    assert stratum_names([0, 2, 3, 5]) == ["0-1 turns", "2 turns", "3-4 turns", "5+ turns"]
    assert [stratum_of(t, [0, 1, 3]) for t in range(6)] == ["line of sight", "1-2 turns",
            "1-2 turns", "3+ turns", "3+ turns", "3+ turns"]  # fmt: skip
    for bad in ([], [1, 2], [0, 2, 2], [0, 1.5]):
        with pytest.raises(ValueError, match="strata bounds"):
            check_bounds(bad)
    with pytest.raises(ValueError, match=">= 0"):
        stratum_of(-1, BOUNDS)


def test_the_mix_counts_distinct_instances_per_map_set():
    turns = {0: 0, 1: 2, 2: 5, 3: 0, 4: 1}
    table = pd.DataFrame({"instance": [0, 0, 1, 2, 2, 3, 4],
                          "map_set": ["a", "a", "a", "a", "a", "b", "b"]})  # fmt: skip
    got = mix(table, assign(turns, BOUNDS), BOUNDS)
    assert got == {"a": {"line of sight": 1, "1-2 turns": 1, "3+ turns": 1},
                   "b": {"line of sight": 1, "1-2 turns": 1, "3+ turns": 0}}  # fmt: skip
