"""Which regime cells are the same run, decided from their effective settings.

* **Goal radius.** ``null`` means eta; at an unlimited step (eta = inf) ``null`` and ``.inf``
  are the same radius (inf): the goal radius is moot there.
* **Shrinking radius.** ``min(gamma sqrt(log n / n), eta)`` with ``n = max(nodes, 2)``
  (:func:`vnrrt.planners.rrt_star.near_radius`). ``f(n) = sqrt(log n / n)`` peaks at
  ``n = e`` and decreases after it, so over tree sizes ``2..N`` its minimum is
  ``min(f(2), f(N))``: the radius stays at eta for a whole run of at most ``N`` nodes iff
  ``gamma min(f(2), f(N)) >= eta`` (:func:`stays_at_eta`), and such a run is the run of a
  fixed radius eta (``fixed1``), sample for sample (the same seeds). Gamma is
  ``gamma_factor`` x the map's RRT* bound ``2 sqrt(1.5) sqrt(free cells / pi)``
  (:func:`rrt_gamma`).

  *Before running* (``N`` = the iteration budget + 2: the root, one node per iteration, the
  goal leaf) this holds only for ``gamma >= eta / f(N)``: at a budget of 200,000 iterations
  ``f(N) = 0.0078``, so on a 200 x 200 map (gamma <= 277) the radius stays at eta for the
  whole budget only for eta <= 2.2 px. *After running*, each run's own tree size decides:
  a cell every run of which kept the radius at eta was a fixed-radius cell
  (:func:`effective_keys`).

Cells with the same effective settings (:func:`cell_key`) are one setting: counted once,
and the per-cell readings corrected for the number of distinct cells (Bonferroni).
"""

from __future__ import annotations

import math

import pandas as pd


def f(n: float) -> float:
    """``sqrt(log n / n)`` at ``max(n, 2)`` nodes."""
    n = max(n, 2)
    return math.sqrt(math.log(n) / n)


def stays_at_eta(gamma: float, eta: float, nodes: float) -> bool:
    """The shrinking radius equals ``eta`` at every tree size from 2 to ``nodes`` (module
    doc); never at an unlimited step."""
    return math.isfinite(eta) and gamma * min(f(2), f(nodes)) >= eta


def rrt_gamma(free_cells: int, factor: float = 1.0) -> float:
    """``factor`` x the RRT* bound ``2 (1 + 1/d)^(1/d) (free / unit-ball area)^(1/d)``, d=2."""
    return factor * 2.0 * math.sqrt(1.5) * math.sqrt(free_cells / math.pi)


def cell_key(settings: dict, always_eta: bool = False) -> tuple:
    """The effective settings ``(eta, near radius, goal radius)`` of a cell's overrides
    (``eta``, ``radius_mode``, ``gamma_factor``, ``fixed_radius``, ``goal_radius``);
    ``always_eta``: its shrinking radius stayed at eta (a fixed radius eta)."""
    eta = float(settings["eta"])
    goal = settings.get("goal_radius")
    goal = math.inf if not math.isfinite(eta) else eta if goal is None else float(goal)
    if settings["radius_mode"] == "fixed":
        radius = ("fixed", float(settings["fixed_radius"]))
    elif always_eta:
        radius = ("fixed", eta)
    else:
        radius = ("shrinking", float(settings.get("gamma_factor", 1.0)))
    return (eta, radius, goal)


def _always_eta(settings: dict, runs: pd.DataFrame, free: dict[int, int]) -> bool:
    """Every run of a shrinking cell kept its radius at eta (its tree size + 1, its map's
    gamma); False for a fixed radius or an unknown map."""
    if settings["radius_mode"] != "shrinking" or runs.empty:
        return False
    factor = float(settings.get("gamma_factor", 1.0))
    for inst, size in zip(runs["instance"], runs["tree_size"], strict=True):
        if int(inst) not in free:
            return False
        if not stays_at_eta(rrt_gamma(free[int(inst)], factor), settings["eta"], size + 1):
            return False
    return True


def effective_keys(table: pd.DataFrame, cells: dict[str, dict],
                   free: dict[int, int] | None) -> dict[str, tuple]:  # fmt: skip
    """``{cell: effective key}`` of the evaluation ``table``'s cells (``cells``: label ->
    settings, the protocol's included) from their runs (module doc); ``free``: each
    instance's free cells (None: settings alone)."""
    by_cell = dict(tuple(table.groupby("regime", sort=False)))
    out = {}
    for label, settings in cells.items():
        runs = by_cell.get(label, table.iloc[:0])
        out[label] = cell_key(settings, free is not None and _always_eta(settings, runs, free))
    return out


def groups(keys: dict[str, tuple]) -> dict[str, list[str]]:
    """``{representative: [cells]}``: cells with equal keys, the first (in ``keys``' order)
    standing for its group."""
    first: dict[tuple, str] = {}
    out: dict[str, list[str]] = {}
    for label, key in keys.items():
        rep = first.setdefault(key, label)
        out.setdefault(rep, []).append(label)
    return out
