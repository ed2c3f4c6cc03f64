"""Samplers for the RRT* core: uniform, heatmap (NRRT*/VNRRT*) and masked (M-VNRRT*).

Every sampler is the same small piece of data, a :class:`Sampler`, read by one compiled
draw, :func:`any_point`: with probability ``mix`` a point is drawn from the heatmap (a pixel
with probability proportional to its weight, then a uniform point inside that pixel),
otherwise uniformly from the whole map ``[0, W) x [0, H)`` (obstacles included, as in
Algorithm 1). ``uniform`` (RRT*) is ``mix = 0``; ``heatmap`` (NRRT* with a path heatmap,
VNRRT* with a vertex heatmap; Algorithm 2) weighs pixels by the heatmap; ``masked``
(M-VNRRT*) by the heatmap with values below ``tau`` set to zero. The same draw serves
informed sampling (inside the ellipse of the points through which a shorter path can run)
and the gap sampler (a share of the samples from the narrow-passage cells of :mod:`.gaps`).

If no positive weight is left, the sampler falls back to uniform (no heatmap draws) and sets
``fallback_uniform``. Huge or tiny weights are scaled by a power of two before they are summed
(the draws stay those of the given weights). Randomness comes from a xoshiro256** generator
seeded by :class:`numpy.random.SeedSequence` (:func:`rng_state`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np
from numba import njit

from vnrrt.grid import GridError

_INV_2_53 = 1.0 / 9007199254740992.0
NO_CELLS = np.zeros(1, np.int64)  # the gap cells of a sampler without (or not yet with) any


class Draws(NamedTuple):
    """A sampler as the compiled draw reads it: heatmap draw probability ``mix``, cumulative
    weights ``cdf`` over flat pixels and the last pixel with weight; the gap sampler: its
    share ``gap_share`` of the samples, the widest passage ``gap_width`` (cells), the
    iterations ``gap_after`` before its first draw, and the first ``n_gaps`` flat indices of
    ``gap_cells`` it draws from (:mod:`.gaps`; ``n_gaps`` -1: not found yet, 0: none)."""

    mix: float
    cdf: np.ndarray
    last: int
    gap_share: float = 0.0
    gap_width: int = 8
    gap_after: int = 0
    gap_cells: np.ndarray = NO_CELLS
    n_gaps: int = 0


def rng_state(seed) -> np.ndarray:
    """Fresh xoshiro256** state ``(4,)`` uint64 from ``seed`` (int >= 0 or tuple of them):
    ``SeedSequence(seed).generate_state(4, np.uint64)``, the all-zero state (the one invalid
    xoshiro state) made ``[1, 0, 0, 0]``."""
    state = np.random.SeedSequence(seed).generate_state(4, dtype=np.uint64)
    if not state.any():
        state[0] = 1
    return state


@njit(cache=True, inline="always")
def _rotl(x, k):
    return (x << np.uint64(k)) | (x >> np.uint64(64 - k))


@njit(cache=True)
def next_double(s: np.ndarray) -> float:
    """Advance xoshiro256** state ``s`` (4,) uint64; return a float in ``[0, 1)``."""
    result = _rotl(s[1] * np.uint64(5), 7) * np.uint64(9)
    t = s[1] << np.uint64(17)
    s[2] ^= s[0]
    s[3] ^= s[1]
    s[1] ^= s[2]
    s[0] ^= s[3]
    s[2] ^= t
    s[3] = _rotl(s[3], 45)
    return float(result >> np.uint64(11)) * _INV_2_53


@dataclass(frozen=True)
class Sampler:
    """A sampling distribution over an ``(H, W)`` map, and the settings it was built with.

    Attributes:
        kind: ``'uniform'``, ``'heatmap'`` or ``'masked'``.
        mix: the probability of a heatmap draw it was built with (0 for uniform).
        cdf: ``(H*W,)`` float64 cumulative weights over flat pixels ``y * W + x``
            (empty for uniform or after a fallback), scaled by a power of two when the raw
            total would overflow or lose precision (:func:`heatmap_sampler`).
        last: index of the last pixel with positive weight (-1 for uniform).
        shape: ``(H, W)`` of the map.
        fallback_uniform: True when a heatmap sampler had no positive weight left.
        tau: the mask threshold of a masked sampler (None for the other kinds).
    """

    kind: str
    mix: float
    cdf: np.ndarray
    last: int
    shape: tuple[int, int]
    fallback_uniform: bool = False
    tau: float | None = None

    def draws(self, *, gap_share=0.0, gap_width=8, gap_after=0, cells=None) -> Draws:
        """This sampler as the compiled draw reads it, with the gap sampler's settings and
        flat ``cells`` (None: pending, found by the run when ``gap_share > 0``). Without
        weights (uniform, or after a fallback) no heatmap draw is made (``mix`` 0)."""
        mix = 0.0 if self.fallback_uniform or self.last < 0 else float(self.mix)
        cdf = self.cdf if self.cdf.size else np.zeros(1)
        n = (-1 if gap_share > 0 else 0) if cells is None else cells.size
        cells = NO_CELLS if cells is None or cells.size == 0 else cells
        return Draws(mix, cdf, max(self.last, 0), float(gap_share), int(gap_width),
                     int(gap_after), cells, n)  # fmt: skip


def uniform_sampler(shape: tuple[int, int]) -> Sampler:
    """Uniform sampler over the ``(H, W)`` map."""
    return Sampler("uniform", 0.0, np.zeros(0), -1, (int(shape[0]), int(shape[1])))


def heatmap_sampler(
    heatmap: np.ndarray, shape: tuple[int, int], *, mix: float = 0.5, tau: float | None = None
) -> Sampler:
    """Heatmap sampler (``tau=None``) or masked sampler (weights below ``tau`` zeroed).

    Args:
        heatmap: ``(H, W)`` finite non-negative values (probabilities or scores), indexed
            ``heatmap[y, x]`` like the grid.
        shape: ``(H, W)`` of the grid; the heatmap must match it.
        mix: probability of drawing from the heatmap in each sample (Algorithm 2: 0.5).
        tau: mask threshold of M-VNRRT*; pixels with value ``< tau`` get zero weight.
    """
    hm = np.asarray(heatmap)
    if hm.shape != tuple(shape):
        raise GridError(f"heatmap has shape {hm.shape}, the grid has shape {tuple(shape)}")
    if not np.issubdtype(hm.dtype, np.number) or np.issubdtype(hm.dtype, np.complexfloating):
        raise GridError(f"heatmap must be real numbers, got dtype {hm.dtype}")
    hm = hm.astype(np.float64)
    if not np.all(np.isfinite(hm)) or hm.min() < 0:
        raise GridError("heatmap values must be finite and >= 0")
    if not 0.0 <= mix <= 1.0:
        raise ValueError(f"mix must be in [0, 1], got {mix}")
    weights = hm if tau is None else np.where(hm >= tau, hm, 0.0)
    kind, tau = ("heatmap", None) if tau is None else ("masked", float(tau))
    flat = _in_range(weights.ravel())
    positive = np.flatnonzero(flat > 0)
    if positive.size == 0:
        return Sampler(kind, float(mix), np.zeros(0), -1, tuple(shape), True, tau)
    cdf = np.cumsum(flat)
    if not math.isfinite(cdf[-1]):  # unreachable after _in_range; never sample from it
        raise GridError(f"heatmap weights sum to {cdf[-1]}, not a finite total")
    return Sampler(kind, float(mix), cdf, int(positive[-1]), tuple(shape), False, tau)


SAFE_TOP = 2.0**960  # weights whose total stays within [2^-960, 2^960] are summed as given


def _in_range(flat: np.ndarray) -> np.ndarray:
    """``flat`` (finite, >= 0) scaled by a power of two when its total would overflow or
    come near the subnormal range, so that the largest weight lies in [0.5, 1). A power of
    two scales every sum exactly, so the draws are those of the given weights; weights whose
    total stays in the safe range (every probability map) are returned as they are, and
    their draws are bit-identical to an unscaled cumulative sum."""
    top = float(flat.max()) if flat.size else 0.0
    if top == 0.0 or (top >= 1.0 / SAFE_TOP and top * flat.size <= SAFE_TOP):
        return flat
    return np.ldexp(flat, -math.frexp(top)[1])


@njit(cache=True, inline="always")
def _below(v, hi):
    """``v`` clamped under ``hi`` (rounding of ``lo + u`` may reach ``hi`` when u ~ 1)."""
    return v if v < hi else hi - 1e-9


@njit(cache=True, inline="always")
def _pixel_point(s, w, d, gap):
    """A uniform point of a pixel of a ``W`` wide map drawn from the sampler ``d``: one of the
    first ``d.n_gaps`` gap cells, uniformly, when ``gap``, else a pixel with probability
    proportional to its weight."""
    if gap:
        i = d.gap_cells[min(int(next_double(s) * d.n_gaps), d.n_gaps - 1)]
    else:
        i = min(np.searchsorted(d.cdf, next_double(s) * d.cdf[d.last], side="right"), d.last)
    px, py = float(i % w), float(i // w)
    return _below(px + next_double(s), px + 1.0), _below(py + next_double(s), py + 1.0)


INFORMED_TRIES = 64  # uniform draws until one lies in both the ellipse and the map
HEATMAP_TRIES = 16  # heatmap draws until one lies in the ellipse


@njit(cache=True, inline="always")
def in_ellipse(x, y, sx, sy, gx, gy, c_best):
    """True when ``(x, y)`` lies in the ellipse with foci start and goal, major axis
    ``c_best``: the points through which a path can be shorter than ``c_best``."""
    return math.hypot(x - sx, y - sy) + math.hypot(x - gx, y - gy) <= c_best


@njit(cache=True)
def ellipse_uniform(s, h, w, sx, sy, gx, gy, c_best):
    """A uniform point of the ellipse (foci start and goal, major axis ``c_best``) inside the
    map ``[0, W) x [0, H)``, by rejection from the smaller of two regions that hold it: the
    ellipse (points outside the map rejected) or the map part of its bounding box (points
    outside the ellipse rejected); acceptance is at least 0.77 over 3,000 random map sizes,
    endpoints and costs. After :data:`INFORMED_TRIES` rejections (never seen) a uniform
    point of the start-goal segment (in both) is returned."""
    c_min = math.hypot(gx - sx, gy - sy)
    a = 0.5 * c_best
    b = 0.5 * math.sqrt(max(c_best * c_best - c_min * c_min, 0.0))
    cos_t, sin_t = ((gx - sx) / c_min, (gy - sy) / c_min) if c_min > 0 else (1.0, 0.0)
    cx, cy = 0.5 * (sx + gx), 0.5 * (sy + gy)
    half_x = math.sqrt((a * cos_t) ** 2 + (b * sin_t) ** 2)  # bounding box half-sides
    half_y = math.sqrt((a * sin_t) ** 2 + (b * cos_t) ** 2)
    x0, x1 = max(cx - half_x, 0.0), min(cx + half_x, float(w))
    y0, y1 = max(cy - half_y, 0.0), min(cy + half_y, float(h))
    from_ellipse = math.pi * a * b < (x1 - x0) * (y1 - y0)
    for _ in range(INFORMED_TRIES):
        if from_ellipse:
            r = math.sqrt(next_double(s))
            th = 2.0 * math.pi * next_double(s)
            ex, ey = a * r * math.cos(th), b * r * math.sin(th)
            x, y = cx + cos_t * ex - sin_t * ey, cy + sin_t * ex + cos_t * ey
            if 0.0 <= x < w and 0.0 <= y < h:
                return x, y
        else:
            x = _below(x0 + next_double(s) * (x1 - x0), x1)
            y = _below(y0 + next_double(s) * (y1 - y0), y1)
            if in_ellipse(x, y, sx, sy, gx, gy, c_best):
                return x, y
    t = next_double(s)
    return sx + t * (gx - sx), sy + t * (gy - sy)


@njit(cache=True, inline="always")
def any_point(s, h, w, d, ellipse):
    """One sample ``(x, y)`` (pixels) of the sampler ``d`` (a :class:`Draws`), ``s`` the rng
    state: with probability ``d.gap_share`` (when gap cells exist) a gap sampler's draw, else
    with probability ``d.mix`` a heatmap draw, else a uniform point of the map (a share or
    mix of 0 spends no random number). ``ellipse`` is ``(informed, sx, sy, gx, gy, c_best)``:
    when informed, a gap or heatmap draw is rejected outside the ellipse of ``c_best`` (at
    most :data:`HEATMAP_TRIES` times, then a uniform point of it: :func:`ellipse_uniform`)."""
    informed, sx, sy, gx, gy, c_best = ellipse
    gap = d.gap_share > 0.0 and d.n_gaps > 0 and next_double(s) < d.gap_share
    if not gap and not (d.mix > 0.0 and next_double(s) < d.mix):
        if informed:
            return ellipse_uniform(s, h, w, sx, sy, gx, gy, c_best)
        return _below(next_double(s) * w, float(w)), _below(next_double(s) * h, float(h))
    for _ in range(HEATMAP_TRIES if informed else 1):
        x, y = _pixel_point(s, w, d, gap)
        if not informed or in_ellipse(x, y, sx, sy, gx, gy, c_best):
            return x, y
    return ellipse_uniform(s, h, w, sx, sy, gx, gy, c_best)


@njit(cache=True)
def _draw(s, count, h, w, d, ellipse):
    out = np.empty((count, 2))
    for k in range(count):
        out[k, 0], out[k, 1] = any_point(s, h, w, d, ellipse)
    return out


def draw(sampler: Sampler, n: int, *, seed=0, ellipse=None, gaps=None) -> np.ndarray:
    """``n`` samples ``(n, 2)`` float64 (x, y) in pixels from ``sampler`` (for tests, plots);
    ``ellipse=(start, goal, c_best)`` draws the informed samples of a run whose best solution
    costs ``c_best``; ``gaps=(share, cells)`` mixes in the gap sampler's draws as a planner
    with ``gap_share=share`` does (``cells``: flat indices, :func:`vnrrt.planners.gaps.
    gap_cells`)."""
    (sx, sy), (gx, gy), c_best = ellipse if ellipse is not None else ((0, 0), (0, 0), 0.0)
    share, cells = (gaps[0], np.asarray(gaps[1], np.int64)) if gaps is not None else (0.0, None)
    d = sampler.draws(gap_share=share, cells=cells)
    ends = (ellipse is not None, float(sx), float(sy), float(gx), float(gy), float(c_best))
    return _draw(rng_state(seed), int(n), *sampler.shape, d, ends)
