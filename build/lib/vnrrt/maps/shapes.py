"""Obstacle shapes drawn with OpenCV on a uint8 occupancy canvas (1 = obstacle).

Every shape is built as a polygon in local coordinates around the origin, rotated by a
random angle and moved to a random centre, so all five kinds get a random orientation.
Coordinates are pixels, (x, y) with y down, as in :mod:`vnrrt.grid`.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import cv2
import numpy as np

SHAPES = ("triangle", "circle", "square", "bar", "u_shape")


def _rotated(poly: np.ndarray, angle: float, center: np.ndarray) -> np.ndarray:
    """Rotate ``(N, 2)`` local points by ``angle`` radians and shift them to ``center``."""
    c, s = math.cos(angle), math.sin(angle)
    rot = np.array([[c, -s], [s, c]])
    return poly @ rot.T + center


def _fill(canvas: np.ndarray, poly: np.ndarray) -> None:
    pts = np.round(poly).astype(np.int32).reshape(-1, 1, 2)
    cv2.fillPoly(canvas, [pts], 1, lineType=cv2.LINE_8)


def _triangle(rng: np.random.Generator, size: float, bar_width: float) -> np.ndarray:
    """A random triangle: three corners at radius ``size/2`` in jittered 120-degree sectors."""
    angles = np.arange(3) * (2 * math.pi / 3) + rng.uniform(-0.4, 0.4, 3)
    return 0.5 * size * np.stack([np.cos(angles), np.sin(angles)], axis=1)


def _square(rng: np.random.Generator, size: float, bar_width: float) -> np.ndarray:
    h = 0.5 * size
    return np.array([[-h, -h], [h, -h], [h, h], [-h, h]])


def _bar(rng: np.random.Generator, size: float, bar_width: float) -> np.ndarray:
    """A long thin rectangle: length ``2 * size``, width ``bar_width``."""
    h, t = size, 0.5 * bar_width
    return np.array([[-h, -t], [h, -t], [h, t], [-h, t]])


def _u_shape(rng: np.random.Generator, size: float, bar_width: float) -> np.ndarray:
    """A U of outer side ``size`` and wall thickness ``bar_width``, opening towards +y."""
    a, t = 0.5 * size, min(bar_width, 0.3 * size)
    return np.array(
        [[-a, -a], [a, -a], [a, a], [a - t, a], [a - t, -a + t], [-a + t, -a + t], [-a + t, a],
         [-a, a]]
    )  # fmt: skip


_POLYGONS: dict[str, Callable[[np.random.Generator, float, float], np.ndarray]] = {
    "triangle": _triangle,
    "square": _square,
    "bar": _bar,
    "u_shape": _u_shape,
}


def draw_shape(
    canvas: np.ndarray,
    kind: str,
    center: np.ndarray,
    size: float,
    angle: float,
    bar_width: float,
    rng: np.random.Generator,
) -> None:
    """Draw one obstacle of ``kind`` (one of :data:`SHAPES`) in place on ``canvas`` (H, W).

    ``center`` (x, y) and ``size`` (characteristic extent) are in pixels, ``angle`` in
    radians; ``rng`` draws the shape's own random details (triangle corners).
    """
    if kind == "circle":
        cx, cy = (int(round(v)) for v in center)
        cv2.circle(canvas, (cx, cy), max(1, int(round(size / 2))), 1, -1, lineType=cv2.LINE_8)
        return
    if kind not in _POLYGONS:
        raise ValueError(f"unknown obstacle shape {kind!r}; known: {', '.join(SHAPES)}")
    _fill(canvas, _rotated(_POLYGONS[kind](rng, size, bar_width), angle, center))
