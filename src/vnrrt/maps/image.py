"""Floor maps from PNG files: one reading, whatever the image's bit depth, colour type or
transparency (used by the ``vnrrt`` command line; :func:`read_map_image` for the library).

1. The PNG is decoded as stored: 8 or 16 bits per value (1, 2 and 4-bit images expanded to
   8 bits as PNG prescribes: 1-bit black/white become 0/255); gray, gray+alpha, RGB, RGBA or
   palette. Colour becomes gray (luminance 0.299 R + 0.587 G + 0.114 B, values kept as
   stored).
2. **Class map**: when every pixel is opaque, every value is 0, 1, 2 or 3 and one is not 0,
   the values are the paper's pixel classes (:mod:`vnrrt.grid`): 0 free, 1 obstacle,
   2 start, 3 goal. The first start and goal pixels (row by row) give the endpoints (their
   cell centres); start and goal pixels are free. So a 0/1 occupancy image reads as one
   (1 = obstacle), in 8 or 16 bits.
3. **Otherwise a picture**: the gray level ``l = value / (2^bits - 1)`` in [0, 1], drawn over
   white where it is transparent (``a l + 1 - a`` for alpha ``a`` in [0, 1]); dark pixels
   (below 0.5) are obstacles. Fully transparent pixels are thus free, and an all-black
   image is all obstacle, in 8 or 16 bits alike.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from vnrrt.grid import FREE, GOAL, OBSTACLE, START, GridError

DARK = 0.5  # a picture's pixels darker than this (gray level in [0, 1], over white) are obstacles


def decode_png(path: str | Path) -> tuple[np.ndarray, np.ndarray, int]:
    """``(gray, alpha, full)``: gray values ``(H, W)`` as stored (uint8 or uint16), alpha
    ``(H, W)`` float64 in [0, 1] (1 without an alpha channel) and the value of full white
    (255 or 65535). :class:`~vnrrt.grid.GridError` when the file is not a readable PNG."""
    import cv2

    img = cv2.imread(str(path), cv2.IMREAD_UNCHANGED)
    if img is None or img.dtype not in (np.uint8, np.uint16) or img.ndim not in (2, 3):
        raise GridError(f"cannot read {path} as an 8- or 16-bit PNG image")
    full = int(np.iinfo(img.dtype).max)
    if img.ndim == 2:
        return img, np.ones(img.shape), full
    if img.shape[2] not in (3, 4):
        raise GridError(f"{path}: unsupported image with {img.shape[2]} channels")
    gray = cv2.cvtColor(np.ascontiguousarray(img[..., :3]), cv2.COLOR_BGR2GRAY)
    alpha = img[..., 3] / full if img.shape[2] == 4 else np.ones(gray.shape)
    return gray, alpha, full


def _first_pixel(classes: np.ndarray, value: int) -> tuple[float, float] | None:
    """Centre ``(x + 0.5, y + 0.5)`` of the first pixel (row by row) equal to ``value``."""
    ys, xs = np.nonzero(classes == value)
    return (float(xs[0]) + 0.5, float(ys[0]) + 0.5) if len(xs) else None


def map_from_image(gray: np.ndarray, alpha: np.ndarray, full: int) -> dict:
    """``{"grid": (H, W) uint8 0/1, "start": (x, y) | None, "goal": (x, y) | None}`` of a
    decoded image (:func:`decode_png`), read as the module doc says."""
    opaque = bool(np.all(alpha >= 1.0))
    if opaque and gray.max() > FREE and gray.max() <= GOAL:  # a class map
        grid = (gray == OBSTACLE).astype(np.uint8)
        return {"grid": grid, "start": _first_pixel(gray, START), "goal": _first_pixel(gray, GOAL)}
    level = alpha * (gray / float(full)) + (1.0 - alpha)  # over white
    return {"grid": (level < DARK).astype(np.uint8), "start": None, "goal": None}


def read_map_image(path: str | Path) -> dict:
    """The map of PNG file ``path`` (module doc): ``{"grid": (H, W) uint8 (1 = obstacle,
    indexed grid[y, x]), "start": (x, y) or None, "goal": (x, y) or None}`` (points in
    pixels; only class maps hold endpoints)."""
    return map_from_image(*decode_png(path))
