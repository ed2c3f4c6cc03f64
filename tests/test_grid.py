"""Validation of grids, cells and points in vnrrt.grid: clear errors naming the problem."""

import numpy as np
import pytest

from vnrrt.grid import GridError, as_cell, as_occupancy, as_point, cell_center, point_to_cell


def test_occupancy_accepts_bool_and_int_and_normalises():
    g = np.array([[0, 3], [0, 0]], dtype=np.int32)
    occ = as_occupancy(g)
    assert occ.dtype == np.uint8 and occ.tolist() == [[0, 1], [0, 0]]
    assert as_occupancy(g.astype(bool)).tolist() == occ.tolist()


@pytest.mark.parametrize(
    ("grid", "message"),
    [
        (np.zeros((4, 4, 3), np.uint8), "2-D"),
        (np.zeros((1, 5), np.uint8), "at least 2x2"),
        (np.zeros((4, 4), np.float64), "dtype"),
        (np.zeros((4, 4), object), "dtype"),
    ],
)
def test_occupancy_rejects_bad_grids(grid, message):
    with pytest.raises(GridError, match=message):
        as_occupancy(grid)


def test_cell_validation_names_the_problem():
    g = np.zeros((5, 6), np.uint8)
    g[2, 3] = 1
    assert as_cell(g, (5, 4), "start") == (5, 4)
    with pytest.raises(GridError, match="start .* outside"):
        as_cell(g, (6, 0), "start")
    with pytest.raises(GridError, match="goal \\(3, 2\\) lies on an obstacle"):
        as_cell(g, (3, 2), "goal")
    with pytest.raises(GridError, match="integer cell"):
        as_cell(g, (1.5, 2), "start")


def test_point_validation_and_cell_convention():
    g = np.zeros((5, 6), np.uint8)
    g[2, 3] = 1  # row y=2, column x=3
    with pytest.raises(GridError, match="obstacle"):
        as_point(g, (3.99, 2.01), "start")  # inside cell (x=3, y=2)
    assert as_point(g, (2.99, 2.5), "start") == (2.99, 2.5)
    with pytest.raises(GridError, match="outside"):
        as_point(g, (6.0, 1.0), "goal")
    with pytest.raises(GridError, match="finite"):
        as_point(g, (np.nan, 1.0), "goal")
    assert point_to_cell(cell_center([[3, 2]])).tolist() == [[3, 2]]
