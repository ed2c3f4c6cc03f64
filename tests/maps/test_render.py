"""Network inputs and targets against hand-made instances: classes, colours, disks, dilation."""

import numpy as np
import pytest

from vnrrt.data.targets import cells_mask, check_target, dilate, label_masks, target_mask
from vnrrt.grid import GridError, disk
from vnrrt.maps.render import (
    IMAGENET_MEAN,
    IMAGENET_STD,
    PALETTE,
    class_map,
    colorize,
    render_instance,
    to_input,
)

# A 7x7 map with one obstacle cell at (x=3, y=2), right of the start (2, 2); goal (5, 5).
GRID = np.zeros((7, 7), np.uint8)
GRID[2, 3] = 1
# Start and goal as radius-1 disks (the 4-neighbourhood), drawn over free cells only.
EXPECTED = np.array(
    [
        [0, 0, 0, 0, 0, 0, 0],
        [0, 0, 2, 0, 0, 0, 0],
        [0, 2, 2, 1, 0, 0, 0],
        [0, 0, 2, 0, 0, 0, 0],
        [0, 0, 0, 0, 0, 3, 0],
        [0, 0, 0, 0, 3, 3, 3],
        [0, 0, 0, 0, 0, 3, 0],
    ],
    np.uint8,
)


def test_disk_stencils():
    assert disk(0).tolist() == [[True]]
    assert disk(0.9).tolist() == [[True]]
    assert disk(1).astype(int).tolist() == [[0, 1, 0], [1, 1, 1], [0, 1, 0]]
    assert disk(1.5).all() and disk(1.5).shape == (3, 3)
    assert disk(2).sum() == 13  # 1 + 4 + 4 diagonal + 4 at distance 2
    with pytest.raises(GridError, match="radius"):
        disk(-1)


def test_class_map_of_a_hand_made_instance():
    classes = class_map(GRID, (2, 2), (5, 5), marker_radius=1)
    np.testing.assert_array_equal(classes, EXPECTED)
    single = class_map(GRID, (2, 2), (5, 5), marker_radius=0)
    assert (single == 2).sum() == 1 and single[2, 2] == 2 and single[5, 5] == 3
    assert (single == 1).sum() == 1  # the obstacle


def test_markers_are_clipped_at_the_border_and_goal_wins_overlaps():
    grid = np.zeros((5, 5), np.uint8)
    classes = class_map(grid, (0, 0), (2, 0), marker_radius=2)
    assert classes[0, 0] == 2 and classes[0, 2] == 3  # the cells themselves
    assert classes[0, 1] == 3 and classes[1, 1] == 3  # in both disks: goal
    assert classes[2, 0] == 2 and classes[4, 4] == 0  # (0, 2) is 2 px from the start only


def test_start_or_goal_on_an_obstacle_is_refused():
    with pytest.raises(GridError, match="start"):
        class_map(GRID, (3, 2), (5, 5))
    with pytest.raises(GridError, match="goal"):
        class_map(GRID, (0, 0), (9, 9))


def test_colours_are_distinct_and_the_input_is_normalised():
    assert len({tuple(c) for c in PALETTE}) == 4
    rgb = colorize(EXPECTED)
    assert rgb.shape == (7, 7, 3) and rgb.dtype == np.uint8
    np.testing.assert_array_equal(rgb[5, 5], PALETTE[3])
    unit = to_input(rgb, "unit")
    assert unit.shape == (3, 7, 7) and unit.dtype == np.float32
    assert unit[:, 0, 0].tolist() == [1.0, 1.0, 1.0] and unit[:, 2, 3].tolist() == [0, 0, 0]
    x = render_instance(GRID, (2, 2), (5, 5), 1, "imagenet")
    np.testing.assert_allclose(x[:, 0, 0], (1.0 - IMAGENET_MEAN) / IMAGENET_STD, rtol=1e-6)
    with pytest.raises(ValueError, match="normalize"):
        to_input(rgb, "zscore")


def test_dilation_and_cell_masks():
    cells = np.array([[1, 1], [4, 3]])  # (x, y)
    mask = cells_mask(cells, (5, 6))
    assert mask.sum() == 2 and mask[1, 1] and mask[3, 4]
    grown = cells_mask(cells, (5, 6), radius=1)
    assert grown.sum() == 10  # two plus shapes, none clipped
    assert grown[0, 1] and grown[1, 0] and not grown[0, 0]
    np.testing.assert_array_equal(dilate(mask, 0), mask)
    corner = np.zeros((4, 4), bool)
    corner[0, 0] = True
    assert dilate(corner, 1.5).sum() == 4  # the 3x3 block, clipped to the map


def test_vertex_and_path_targets():
    path = np.array([[0, 0], [1, 1], [2, 2], [3, 2], [4, 2]])
    vertices = path[[0, 2, 4]]
    vt = target_mask(path, vertices, (5, 5), "vertex")
    pt = target_mask(path, vertices, (5, 5), "path")
    assert vt.sum() == 3 and pt.sum() == 5 and not (vt & ~pt).any()
    # plus shapes at (0,0) clipped to 3 cells, (2,2) 5 cells, (4,2) clipped to 4; (3,2) shared
    assert target_mask(path, vertices, (5, 5), "vertex", 1).sum() == 3 + 5 + 4 - 1
    with pytest.raises(ValueError, match="unknown target"):
        check_target("corner", 0)
    with pytest.raises(ValueError, match="radius"):
        check_target("path", -1)
    with pytest.raises(ValueError, match="endpoints 'start'"):
        check_target("vertex", 0, "start")


@pytest.mark.parametrize("radius", [0, 1])
def test_target_endpoints_options(radius):
    """``both`` keeps start (0,0) and goal (4,2), ``goal`` drops the start, ``none`` both;
    the same pixels for either kind, each dilated by the same disk."""
    path = np.array([[0, 0], [1, 1], [2, 2], [3, 2], [4, 2]])
    vertices = path[[0, 2, 4]]
    for kind, cells in (("vertex", vertices), ("path", path)):
        for ends, dropped in (("both", []), ("goal", [0]), ("none", [0, len(cells) - 1])):
            got = target_mask(path, vertices, (5, 5), kind, radius, ends)
            want = cells_mask(np.delete(cells, dropped, axis=0), (5, 5), radius)
            np.testing.assert_array_equal(got, want)
    none = target_mask(path, vertices, (5, 5), "vertex", 0, "none")
    assert none.sum() == 1 and none[2, 2]  # only the interior vertex (2, 2)


def test_label_masks_split_the_vertices():
    path = np.array([[0, 0], [1, 1], [2, 2], [3, 2], [4, 2]])
    m = label_masks(path, path[[0, 2, 4]], (5, 5))
    assert m["path"].sum() == 5 and m["vertices"].sum() == 3
    assert m["interior"].sum() == 1 and m["interior"][2, 2]
    assert m["endpoints"].sum() == 2 and m["endpoints"][0, 0] and m["endpoints"][2, 4]
    np.testing.assert_array_equal(m["interior"] | m["endpoints"], m["vertices"])
