"""Map images: the same reading at every bit depth and colour type, transparency drawn over
white, 0/1 occupancy and class maps read by value; checked against the array each image
was made from."""

import cv2
import numpy as np
import pytest
from PIL import Image

from vnrrt.grid import GridError
from vnrrt.maps.image import read_map_image


def picture_levels() -> np.ndarray:
    """Gray levels (40, 60) in [0, 1]: light floor, a dark wall, a mid-dark block (obstacle,
    0.45) and a mid-light block (free, 0.6), none within a quantisation step of 0.5."""
    levels = np.full((40, 60), 0.9)
    levels[:, 28:31] = 0.3
    levels[5:12, 5:15] = 0.45
    levels[25:35, 40:55] = 0.6
    return levels


def save_gray(path, levels: np.ndarray, bits: int, rgb: bool = False) -> None:
    full = 2**bits - 1
    values = np.round(levels * full).astype(np.uint8 if bits == 8 else np.uint16)
    cv2.imwrite(str(path), np.dstack([values] * 3) if rgb else values)


@pytest.mark.parametrize(("bits", "rgb"), [(8, False), (16, False), (8, True), (16, True)])
def test_a_picture_reads_the_same_at_8_and_16_bits_gray_or_rgb(tmp_path, bits, rgb):
    levels = picture_levels()
    save_gray(tmp_path / "map.png", levels, bits, rgb)
    got = read_map_image(tmp_path / "map.png")
    np.testing.assert_array_equal(got["grid"], levels < 0.5)
    assert got["start"] is None and got["goal"] is None


def test_a_palette_and_a_one_bit_picture_read_by_their_gray_levels(tmp_path):
    levels = picture_levels()
    shades = np.unique(levels)  # 4 gray levels -> palette indices
    index = np.searchsorted(shades, levels).astype(np.uint8)
    img = Image.fromarray(index, "P")
    img.putpalette([int(round(255 * s)) for s in shades for _ in range(3)])
    img.save(tmp_path / "palette.png")
    np.testing.assert_array_equal(read_map_image(tmp_path / "palette.png")["grid"], levels < 0.5)
    Image.fromarray(levels >= 0.5).save(tmp_path / "bits.png")  # mode "1": white = free
    assert Image.open(tmp_path / "bits.png").mode == "1"
    np.testing.assert_array_equal(read_map_image(tmp_path / "bits.png")["grid"], levels < 0.5)


@pytest.mark.parametrize("bits", [8, 16])
def test_transparent_pixels_are_drawn_over_white(tmp_path, bits):
    """Black ink at alpha a shows as gray 1 - a over white: transparent background is free,
    opaque or mostly opaque ink is an obstacle, faint ink is not."""
    full = 2**bits - 1
    alpha = np.zeros((40, 60))
    alpha[:, 28:31] = 1.0  # opaque black wall
    alpha[5:12, 5:15] = 0.8  # mostly opaque: gray 0.2
    alpha[25:35, 40:55] = 0.3  # faint: gray 0.7
    bgra = np.zeros((40, 60, 4), np.uint8 if bits == 8 else np.uint16)  # black everywhere
    bgra[..., 3] = np.round(alpha * full)
    cv2.imwrite(str(tmp_path / "ink.png"), bgra)
    np.testing.assert_array_equal(read_map_image(tmp_path / "ink.png")["grid"], alpha > 0.5)


def test_gray_with_alpha_reads_like_rgba(tmp_path):
    levels, alpha = picture_levels(), np.ones((40, 60))
    alpha[:20] = 0.0  # the top half transparent: free whatever its gray
    la = np.dstack([np.round(levels * 255), np.round(alpha * 255)]).astype(np.uint8)
    Image.fromarray(la, "LA").save(tmp_path / "la.png")
    want = (levels < 0.5) & (alpha > 0.5)
    np.testing.assert_array_equal(read_map_image(tmp_path / "la.png")["grid"], want)


@pytest.mark.parametrize("dtype", [np.uint8, np.uint16])
def test_a_0_1_occupancy_image_reads_as_occupancy(tmp_path, dtype):
    occupancy = (np.random.default_rng(0).random((30, 50)) < 0.3).astype(dtype)
    cv2.imwrite(str(tmp_path / "occ.png"), occupancy)
    got = read_map_image(tmp_path / "occ.png")
    np.testing.assert_array_equal(got["grid"], occupancy)
    assert got["start"] is None and got["goal"] is None


@pytest.mark.parametrize("dtype", [np.uint8, np.uint16])
def test_a_class_map_gives_its_obstacles_and_first_start_and_goal_pixels(tmp_path, dtype):
    classes = np.zeros((30, 50), dtype)
    classes[:, 20:22] = 1
    classes[4, 3], classes[9, 2] = 2, 2  # the first start pixel row by row is (3, 4)
    classes[25, 45] = 3
    cv2.imwrite(str(tmp_path / "classes.png"), classes)
    got = read_map_image(tmp_path / "classes.png")
    np.testing.assert_array_equal(got["grid"], classes == 1)
    assert got["start"] == (3.5, 4.5) and got["goal"] == (45.5, 25.5)


def test_black_is_all_obstacle_white_all_free_and_garbage_is_refused(tmp_path):
    for bits in (8, 16):
        save_gray(tmp_path / "black.png", np.zeros((20, 20)), bits)
        assert read_map_image(tmp_path / "black.png")["grid"].all()
        save_gray(tmp_path / "white.png", np.ones((20, 20)), bits)
        assert not read_map_image(tmp_path / "white.png")["grid"].any()
    (tmp_path / "bad.png").write_bytes(b"not a png")
    with pytest.raises(GridError, match="cannot read .*bad.png"):
        read_map_image(tmp_path / "bad.png")
