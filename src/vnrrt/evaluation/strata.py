"""Turning-point strata: instances grouped by how many times their exact optimum turns.

The exact continuous optimum (:func:`vnrrt.search.any_angle_path`, stored per instance in the
instances file) is a taut polyline whose interior points are convex obstacle corners; its
*turning points* are those interior points (straight-on points are dropped by the search).
An instance whose optimum has none is *line of sight*: there is nothing between start and
goal for a vertex network to predict.

Strata are declared in ``conf/stats`` (``stats.strata``) by their lower bounds: ``[0, 1, 3]``
gives ``0`` (line of sight), ``1-2`` and ``3+`` turning points. Every claim is read per
stratum as well as pooled (:mod:`vnrrt.studies.paper_comparison.claims`).
"""

from __future__ import annotations

from collections.abc import Mapping
from itertools import pairwise

import numpy as np
import pandas as pd


def turning_points(points: np.ndarray) -> int:
    """Interior vertices of an exact optimum ``points`` (K, 2) (start and goal included)."""
    points = np.asarray(points)
    if points.ndim != 2 or points.shape[1] != 2 or len(points) < 2:
        raise ValueError(f"an exact path is (K >= 2, 2) points, got shape {points.shape}")
    return len(points) - 2


def check_bounds(bounds) -> list[int]:
    """``bounds`` as a list of ints: strictly increasing, starting at 0 (else ValueError)."""
    b = [int(v) for v in bounds]
    if not b or b[0] != 0 or any(x >= y for x, y in pairwise(b)) or b != list(bounds):
        raise ValueError(f"strata bounds must be increasing integers from 0, got {list(bounds)}")
    return b


def stratum_names(bounds) -> list[str]:
    """Each stratum's name: ``line of sight`` for ``[0, 1)``, ``1-2 turns``, ``3+ turns``."""
    b = check_bounds(bounds)
    names = []
    for lo, hi in zip(b, [*b[1:], None]):
        if hi is None:
            names.append(f"{lo}+ turns")
        elif (lo, hi) == (0, 1):
            names.append("line of sight")
        elif hi - 1 == lo:
            names.append(f"{lo} turn{'s' if lo != 1 else ''}")
        else:
            names.append(f"{lo}-{hi - 1} turns")
    return names


def stratum_of(turns: int, bounds) -> str:
    """The name of the stratum (:func:`stratum_names`) holding ``turns`` turning points."""
    if turns < 0:
        raise ValueError(f"a turning-point count is >= 0, got {turns}")
    b = check_bounds(bounds)
    return stratum_names(b)[int(np.searchsorted(b, turns, side="right")) - 1]


def assign(turns: Mapping[int, int], bounds) -> dict[int, str]:
    """``{instance: stratum name}`` from ``{instance: turning points}``."""
    return {int(i): stratum_of(int(t), bounds) for i, t in turns.items()}


def mix(table: pd.DataFrame, strata: Mapping[int, str], bounds) -> dict[str, dict[str, int]]:
    """``{map_set: {stratum: instances}}``: how many distinct instances of each map set of a
    trial ``table`` fall in each stratum (every stratum listed, zeros included)."""
    names = stratum_names(bounds)
    out = {}
    for map_set, sub in table.groupby("map_set", sort=False):
        labels = [strata[int(i)] for i in pd.unique(sub["instance"])]
        out[str(map_set)] = {n: labels.count(n) for n in names}
    return out
