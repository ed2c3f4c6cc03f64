"""An instance (grid, start, goal) as the network's input image (paper, VertexNet: "an RGB
image representing a floor map, where obstacles, source, and target points are differentiated
by distinct colors").

Two steps, both deterministic and cheap enough to run in the data loader (no images on disk):

1. :func:`class_map`: ``(H, W)`` uint8 pixel classes of :mod:`vnrrt.grid` (0 free, 1 obstacle,
   2 start, 3 goal). Start and goal are small disks (:func:`vnrrt.grid.disk`) of
   ``marker_radius`` pixels around their cells, drawn over free cells only so the obstacles next
   to them stay visible; where the two disks overlap the goal's wins, but the start and goal
   cells themselves always keep their class.
2. :func:`colorize` with :data:`PALETTE` gives ``(H, W, 3)`` uint8 RGB, and :func:`to_input`
   the ``(3, H, W)`` float32 network input in [0, 1], optionally ImageNet-normalised.
"""

from __future__ import annotations

import numpy as np

from vnrrt.grid import FREE, GOAL, OBSTACLE, START, as_cell, as_occupancy, disk

# RGB of each pixel class: free white, obstacle black, start green, goal red.
PALETTE = np.zeros((4, 3), np.uint8)
PALETTE[FREE], PALETTE[OBSTACLE] = (255, 255, 255), (0, 0, 0)
PALETTE[START], PALETTE[GOAL] = (0, 170, 0), (220, 0, 0)

# torchvision's ImageNet statistics (the encoder's expected input when its weights are loaded).
IMAGENET_MEAN = np.array([0.485, 0.456, 0.406], np.float32)
IMAGENET_STD = np.array([0.229, 0.224, 0.225], np.float32)
NORMALIZATIONS = ("imagenet", "unit")


def _stamp(classes: np.ndarray, free: np.ndarray, cell, radius: float, value: int) -> None:
    """Set the free cells of the ``radius`` disk around ``cell`` (x, y) to ``value``."""
    h, w = classes.shape
    x, y = cell
    k = int(np.floor(radius))
    dy, dx = np.nonzero(disk(radius))
    xs, ys = x + dx - k, y + dy - k
    keep = (xs >= 0) & (xs < w) & (ys >= 0) & (ys < h)
    xs, ys = xs[keep], ys[keep]
    keep = free[ys, xs]
    classes[ys[keep], xs[keep]] = value


def class_map(grid: np.ndarray, start, goal, marker_radius: float = 2.0) -> np.ndarray:
    """Pixel classes ``(H, W)`` uint8 (0 free, 1 obstacle, 2 start, 3 goal) of one instance.

    Args:
        grid: ``(H, W)`` occupancy, nonzero = obstacle, indexed ``grid[y, x]``.
        start, goal: free integer cells ``(x, y)``.
        marker_radius: radius in pixels of the start and goal disks (0: single cells).
    """
    occ = as_occupancy(grid)
    s, g = as_cell(occ, start, "start"), as_cell(occ, goal, "goal")
    classes = occ.copy()  # 0 free, 1 obstacle
    free = occ == 0
    _stamp(classes, free, s, marker_radius, START)
    _stamp(classes, free, g, marker_radius, GOAL)
    classes[s[1], s[0]], classes[g[1], g[0]] = START, GOAL  # the cells themselves always show
    return classes


def colorize(classes: np.ndarray) -> np.ndarray:
    """RGB ``(..., H, W, 3)`` uint8 of pixel classes ``(..., H, W)`` through :data:`PALETTE`."""
    return PALETTE[np.asarray(classes)]


def to_input(rgb: np.ndarray, normalize: str = "imagenet") -> np.ndarray:
    """Network input ``(3, H, W)`` float32 from RGB ``(H, W, 3)`` uint8: scaled to [0, 1],
    then ``(x - mean) / std`` with ImageNet statistics when ``normalize == "imagenet"``."""
    if normalize not in NORMALIZATIONS:
        raise ValueError(f"normalize must be one of {NORMALIZATIONS}, got {normalize!r}")
    x = rgb.astype(np.float32) / 255.0  # (H, W, 3)
    if normalize == "imagenet":
        x = (x - IMAGENET_MEAN) / IMAGENET_STD
    return np.ascontiguousarray(x.transpose(2, 0, 1))


def render_instance(
    grid: np.ndarray, start, goal, marker_radius: float = 2.0, normalize: str = "imagenet"
) -> np.ndarray:
    """The network input ``(3, H, W)`` float32 of one instance (:func:`class_map`,
    :func:`colorize`, :func:`to_input`)."""
    return to_input(colorize(class_map(grid, start, goal, marker_radius)), normalize)
