"""Vertex extraction: every case of the paper's Fig. 2, corners, endpoints, masks."""

import numpy as np
import pytest

from vnrrt.grid import MOVES
from vnrrt.search import path_mask, path_vertices, vertex_indices

E, S, W, N, SE, SW, NW, NE = range(8)


def walk(codes, start=(50, 50)):
    """Cells (T+1, 2) visited from ``start`` by chain codes (E, S, W, N, SE, SW, NW, NE)."""
    return np.vstack([start, start + np.cumsum(MOVES[codes], axis=0)])


@pytest.mark.parametrize("code", range(8))
def test_fig2a_straight_lines_have_only_endpoints(code):
    path = walk([code] * 12)
    assert vertex_indices(path).tolist() == [0, 12]


@pytest.mark.parametrize("pair", [(E, NE), (N, NE), (S, SW), (E, SE), (W, NW)])
def test_fig2b_two_move_zigzags_are_straight(pair):
    path = walk(list(pair) * 8)  # e.g. E,NE,E,NE: straight at step size 2
    assert vertex_indices(path).tolist() == [0, len(path) - 1]


@pytest.mark.parametrize("triple", [(E, E, NE), (E, NE, NE), (N, N, NW), (S, SE, SE)])
def test_fig2c_three_move_zigzags_are_straight(triple):
    path = walk(list(triple) * 6)  # e.g. E,E,NE: straight at step size 3
    assert vertex_indices(path).tolist() == [0, len(path) - 1]


def test_a_right_angle_corner_is_one_vertex():
    path = walk([E] * 6 + [S] * 6)
    assert vertex_indices(path).tolist() == [0, 6, 12]
    assert path_vertices(path).tolist() == [[50, 50], [56, 50], [56, 56]]


def test_a_45_degree_turn_is_one_vertex():
    path = walk([E] * 8 + [SE] * 8)
    assert vertex_indices(path).tolist() == [0, 8, 16]


def test_zigzag_changing_slope_gets_a_vertex_at_the_change():
    # slope-1/2 zigzag, then straight diagonal: the path bends once, near the change
    path = walk([E, NE] * 6 + [NE] * 8)
    inner = vertex_indices(path)[1:-1]
    assert 1 <= len(inner) <= 2 and all(9 <= i <= 14 for i in inner)


def test_single_step_change_inside_a_straight_line_is_not_every_point():
    # a U-turn-like detour: E x5, N x3, W x5 has exactly two corners
    path = walk([E] * 5 + [N] * 3 + [W] * 5)
    assert vertex_indices(path).tolist() == [0, 5, 8, 13]


def test_endpoints_and_degenerate_paths():
    assert vertex_indices(np.array([[3, 4]])).tolist() == [0]
    assert vertex_indices(walk([E])).tolist() == [0, 1]
    with pytest.raises(ValueError, match="T\\+1, 2"):
        vertex_indices(np.zeros((3, 3), int))


def test_path_mask_marks_exactly_the_path_cells():
    path = walk([E] * 3 + [S] * 2, start=(1, 1))
    mask = path_mask(path, (8, 8))
    assert mask.sum() == len(path)
    assert all(mask[y, x] for x, y in path)
