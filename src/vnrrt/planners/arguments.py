"""The checks of a planner's arguments, made before its run: a bad argument is an error that
names it (instead of a crash in compiled code, or a run that spends its whole budget on a
target no path can meet).

Coordinates follow :mod:`vnrrt.grid`: ``occ`` is ``(H, W)`` indexed ``occ[y, x]`` (nonzero =
obstacle), points are continuous ``(x, y)`` pixels, lengths pixels.
"""

from __future__ import annotations

import math
import numbers

import numpy as np

from vnrrt.grid import GridError, as_occupancy, as_point
from vnrrt.planners.collision import segment_free
from vnrrt.planners.config import PLANNERS, USER, PlannerConfig
from vnrrt.planners.samplers import Sampler

SAMPLER_KINDS = {"rrt_star": "uniform", "nrrt_star": "heatmap", "vnrrt_star": "heatmap",
                 "m_vnrrt_star": "masked"}  # fmt: skip
# A stop bound this much (relative) below the straight-line distance is rounding, not a
# mistake: an exact optimum that is the straight segment, summed from its turning points.
STRAIGHT_TOLERANCE = 1e-9


def check_planner(planner) -> None:
    """Raise ``ValueError`` unless ``planner`` is one of :data:`vnrrt.planners.PLANNERS`."""
    if planner not in PLANNERS:
        raise ValueError(f"unknown planner {planner!r}; choose from {PLANNERS}")


def checked_config(config) -> PlannerConfig:
    """``config`` validated (None: the library's default, :data:`~vnrrt.planners.config.USER`,
    ``conf/planner/user.yaml``); ``TypeError`` for anything but a :class:`PlannerConfig`."""
    if config is None:
        return USER
    if not isinstance(config, PlannerConfig):
        raise TypeError(f"config must be a PlannerConfig, got {type(config).__name__}")
    config.validate()  # remembered: a frozen config is checked once
    return config


def occupancy(grid) -> np.ndarray:
    """``grid`` as the core reads it: a C-contiguous 2-D uint8 ``np.ndarray`` (at least 2x2;
    not a subclass) is used as it is (no copy); anything else goes through
    :func:`vnrrt.grid.as_occupancy`."""
    if type(grid) is np.ndarray and grid.dtype == np.uint8 and grid.ndim == 2:  # noqa: SIM102
        if min(grid.shape) >= 2 and grid.flags.c_contiguous:  # (shape read on 2-D arrays only)
            return grid
    return as_occupancy(grid)


def check_sampler(sampler: Sampler, planner: str, shape: tuple[int, int],
                  config: PlannerConfig) -> None:  # fmt: skip
    """Raise ``ValueError`` unless ``sampler`` is what ``planner`` samples from on a map of
    ``shape`` with ``config`` (its kind, shape, ``mix`` and, when masked, ``tau``)."""
    want = SAMPLER_KINDS[planner]
    if sampler.kind != want:
        raise ValueError(f"{planner} samples from a {want} sampler, got a {sampler.kind} one")
    if tuple(sampler.shape) != tuple(shape):
        raise GridError(f"sampler is for shape {sampler.shape}, the grid has shape {shape}")
    if want != "uniform" and sampler.mix != config.mix:
        raise ValueError(f"sampler was built with mix={sampler.mix}, the config has {config.mix}")
    if want == "masked" and sampler.tau != config.tau:
        raise ValueError(f"sampler was built with tau={sampler.tau}, the config has {config.tau}")


def endpoint(occ: np.ndarray, point, name: str) -> tuple[float, float]:
    """``point`` as floats ``(x, y)``: finite, in a free cell, touching no obstacle or border
    (one compiled test; a point that fails it is named by :func:`vnrrt.grid.as_point` or
    here)."""
    try:
        x, y = point
        x, y = float(x), float(y)
    except (TypeError, ValueError):
        x = y = math.nan
    if math.isfinite(x) and math.isfinite(y) and segment_free(occ, x, y, x, y):
        return x, y
    x, y = as_point(occ, point, name)  # names a malformed point, one outside, one in an obstacle
    raise GridError(f"{name} {(x, y)} touches an obstacle cell or the map border")


def check_seed(seed) -> None:
    """Raise ``ValueError`` unless ``seed`` is an int >= 0 or a tuple (or list) of them
    (``numbers.Integral``: numpy ints and bools too)."""
    for part in seed if isinstance(seed, tuple | list) else (seed,):
        if not isinstance(part, numbers.Integral) or part < 0:
            raise ValueError(f"seed must be an int >= 0 or a tuple of them, got {seed!r}")


def check_stop_target(stop, reference_length, start, goal, config=None) -> None:
    """Raise unless ``reference_length`` is None or a real number (``TypeError``) and, for
    ``stop='optimal'``, a positive finite length whose stop bound ``(1 + eps) x
    reference_length`` (``config.eps``; None: :class:`PlannerConfig`'s) is at least the
    straight-line distance from ``start`` to ``goal`` (``ValueError``: no path is shorter);
    for any other stop (the reference is only recorded), a finite length >= 0. ``start`` and
    ``goal`` are checked points ``(x, y)`` (:func:`endpoint`)."""
    if reference_length is None:
        return
    if isinstance(reference_length, bool) or not isinstance(reference_length, numbers.Real):
        raise TypeError(f"reference_length must be a number (pixels) or None, got "
                        f"{type(reference_length).__name__} {reference_length!r}")  # fmt: skip
    ref = float(reference_length)
    if stop != "optimal":
        if not (math.isfinite(ref) and ref >= 0):
            raise ValueError(f"reference_length must be finite and >= 0, got {ref!r}")
        return
    if not (math.isfinite(ref) and ref > 0):
        raise ValueError(
            f"reference_length must be a finite length > 0 for stop='optimal', got {ref!r}"
        )
    eps = PlannerConfig.eps if config is None else config.eps
    straight = math.hypot(goal[0] - start[0], goal[1] - start[1])
    bound = (1.0 + float(eps)) * ref
    if bound < straight * (1.0 - STRAIGHT_TOLERANCE):
        raise ValueError(
            f"reference_length {ref!r}: its stop bound (1 + eps) x {ref!r} = {bound!r} is below "
            f"the straight-line distance {straight!r} from start to goal: no path can meet "
            "stop='optimal'"
        )
