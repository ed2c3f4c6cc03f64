"""The stop target's arguments checked before a run: a ``reference_length`` of the wrong
type, or one that no path can meet, is an error naming the argument (instead of a run that
spends its whole budget on an unreachable target)."""

from __future__ import annotations

import math
import numbers

from vnrrt.planners.config import PlannerConfig

# A stop bound this much (relative) below the straight-line distance is rounding, not a
# mistake: an exact optimum that is the straight segment, summed from its turning points.
STRAIGHT_TOLERANCE = 1e-9


def check_stop_target(stop, reference_length, start, goal, config=None) -> None:
    """Raise unless ``reference_length`` is None or a real number (``TypeError``) and, for
    ``stop='optimal'``, a positive finite length (pixels) whose stop bound ``(1 + eps) x
    reference_length`` (``config.eps``; None: :class:`PlannerConfig`'s) is at least the
    straight-line distance from ``start`` to ``goal`` (continuous ``(x, y)`` pixels;
    ``ValueError``): the cost of any path is at least that distance, so a lower bound could
    never be met; for any other stop (the reference is only recorded), a finite length
    >= 0. Points that are not two numbers each, and a ``config`` that is not a
    :class:`PlannerConfig`, are left to their own checks."""
    if reference_length is None:
        return
    kind = type(reference_length)  # float and int first: the abc check costs a microsecond
    if (
        kind is not float
        and kind is not int
        and (kind is bool or not isinstance(reference_length, numbers.Real))
    ):
        raise TypeError(
            f"reference_length must be a number (pixels) or None, got "
            f"{type(reference_length).__name__} {reference_length!r}"
        )
    ref = float(reference_length)
    if stop != "optimal":  # recorded in the result only (stop 'initial')
        if not (math.isfinite(ref) and ref >= 0):
            raise ValueError(f"reference_length must be finite and >= 0, got {ref!r}")
        return
    if not (math.isfinite(ref) and ref > 0):
        raise ValueError(
            f"reference_length must be a finite length > 0 for stop='optimal', got {ref!r}"
        )
    try:
        (sx, sy), (gx, gy) = ((float(v) for v in p) for p in (start, goal))
    except (TypeError, ValueError):
        return
    eps = PlannerConfig.eps if config is None else getattr(config, "eps", None)
    if not isinstance(config, PlannerConfig | None) or type(eps) not in (float, int):
        return
    straight, bound = math.hypot(gx - sx, gy - sy), (1.0 + float(eps)) * ref
    if bound < straight * (1.0 - STRAIGHT_TOLERANCE):
        raise ValueError(
            f"reference_length {ref!r}: its stop bound (1 + eps) x {ref!r} = {bound!r} is below "
            f"the straight-line distance {straight!r} from start to goal: no path can meet "
            "stop='optimal'"
        )
