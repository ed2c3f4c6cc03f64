"""What physics and the protocol guarantee of every row of a trial table, checked where a
table is read (stage ``evaluate``, ``ideas``, ``budget_report`` and the results bundle's
recompute): a table edited by hand, copied from another run or damaged is refused with
the file, the row and the rule it breaks, instead of feeding the statistics.

Rules (``i``: the row's instance; lengths in pixels, times in seconds):

* **instances**: ``instance`` is one of the instances file's, with its map name and set;
* **keys**: ``stop`` is a stop rule, ``stop_reason`` and ``run_stop_reason`` a planner's
  reasons (equal unless the time budget, applied after the run, stopped it: then
  ``stop_reason`` is ``max_seconds``), ``key`` a
  configuration key whose planner is the row's ``planner`` (and, where the design is known,
  one of its configurations); ``trial`` >= 0;
* **seeds**: ``seed`` is :func:`~vnrrt.evaluation.protocol.trial_seed` of the run's seed,
  the instance, the stop rule and the trial (paired seeds);
* **reference**: the A* optimum of the instance (stop ``initial``/``optimal``) or its
  exact optimum (``optimal_any_angle``), where the instance's optima are known;
* **cost**: a path's cost is at least the instance's exact continuous optimum, less
  :data:`COST_TOLERANCE` (relative): no path is shorter than the shortest;
* **success**: ``success`` exactly when ``stop_reason`` is ``solved``; a success has a
  path, and under the optimal stop rules its cost is within ``(1 + eps)`` x the reference
  (:data:`TARGET_TOLERANCE`); a failure stopped on a budget;
* **budget**: ``iterations`` (samples) in 0 .. ``planner.max_iterations``, ``tree_size``
  in 1 .. iterations + 2 (root, samples, goal), ``collision_checks`` >= 0;
* **times**: ``time_to_stop`` and ``setup_time`` finite and >= 0; ``time_to_first``
  finite, >= 0 and at most ``time_to_stop`` exactly when a path was found within the time
  budget (NaN otherwise: no path, or one found after the time budget, applied after the
  run); each convergence time NaN or within 0 .. ``time_to_stop``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from vnrrt.evaluation.table import CONVERGENCE_COLUMNS, TableError

# Relative slack below the exact optimum: the optimum is computed in float64 from its turning
# points, the tree's costs sum float64 segment lengths; both agree to ~1e-12 relative.
COST_TOLERANCE = 1e-9
# Relative slack above the stop bound (1 + eps) x reference, for the same rounding.
TARGET_TOLERANCE = 1e-9
REASONS = ("solved", "max_iterations", "max_seconds")
# Time columns may differ by the clock's rounding (s): first solution <= stop.
TIME_SLACK = 1e-6


@dataclass(frozen=True)
class Design:
    """What a table's rows must agree with: ``eps`` (``planner.eps``) and
    ``max_iterations`` (the largest ``planner.max_iterations`` of the run's cells); ``seed``
    (the run's, None: unchecked); per instance index its ``names`` (map name, map set),
    ``astar`` and ``exact`` optima (px; an instance missing is unchecked there); ``keys``:
    the configuration keys the design runs (None: any key that parses)."""

    eps: float
    max_iterations: int
    seed: int | None = None
    names: dict[int, tuple[str, str]] = field(default_factory=dict)
    astar: dict[int, float] = field(default_factory=dict)
    exact: dict[int, float] = field(default_factory=dict)
    keys: frozenset[str] | None = None

    def check(self, table: pd.DataFrame, where: str) -> None:
        """:func:`check_table` of ``table`` (read from ``where``) against this design."""
        check_table(table, where, self)


def design_of(instances, eps: float, max_iterations: int, seed: int | None,
              keys=None) -> Design:  # fmt: skip
    """The :class:`Design` of a run on an instances file
    (:class:`vnrrt.data.instances.Instances`) with the configurations ``keys``."""
    a = instances.arrays
    n = len(instances)
    names = {i: (str(a["name"][i]), str(a["map_set"][i])) for i in range(n)}
    return Design(
        eps, max_iterations, seed, names,
        {i: float(a["astar_length"][i]) for i in range(n)},
        {i: float(a["exact_length"][i]) for i in range(n)},
        None if keys is None else frozenset(k.text for k in keys),
    )  # fmt: skip


def check_table(table: pd.DataFrame, where: str, design: Design) -> None:
    """Raise :class:`~vnrrt.evaluation.table.TableError` naming ``where`` (the file), the
    first offending row (its ``seq``) and the rule (module doc) unless every row of
    ``table`` (columns of :mod:`vnrrt.evaluation.table`) keeps every rule."""
    for rule, bad in _violations(table, design):
        bad = np.asarray(bad, dtype=bool)
        if bad.any():
            row = int(np.flatnonzero(bad)[0])
            seq = int(table["seq"].iloc[row])
            raise TableError(
                f"trial table {where}: row seq={seq} (data line {row + 1}) breaks the rule "
                f"'{rule}' (vnrrt.evaluation.invariants; the table was edited, damaged or "
                f"comes from another run: re-run `dvc repro`)"
            )


def _violations(t: pd.DataFrame, d: Design):
    """``(rule, bad rows)`` pairs, in the order of the module doc."""
    yield from _instance_rules(t, d)
    yield from _key_rules(t, d)
    yield from _outcome_rules(t, d)
    yield from _time_rules(t)


def _key_rules(t: pd.DataFrame, d: Design):
    from vnrrt.evaluation.keys import ConfigKey
    from vnrrt.evaluation.protocol import STOPS, trial_seed

    yield "stop is a stop rule", ~t["stop"].isin(STOPS)
    yield "stop_reason is solved, max_iterations or max_seconds", ~t["stop_reason"].isin(REASONS)
    run = t["run_stop_reason"]
    yield "run_stop_reason is solved, max_iterations or max_seconds", ~run.isin(REASONS)
    yield ("run_stop_reason equals stop_reason unless the time budget stopped the run",
           (run != t["stop_reason"]) & (t["stop_reason"] != "max_seconds"))  # fmt: skip
    planners = {}
    for text in t["key"].unique():
        try:
            planners[text] = ConfigKey.parse(text).planner
        except ValueError:
            planners[text] = None
    yield "key is a configuration key", t["key"].map(planners).isna()
    yield "key's planner is the row's planner", t["key"].map(planners) != t["planner"]
    if d.keys is not None:
        yield "key is one of the design's configurations", ~t["key"].isin(d.keys)
    yield "trial >= 0", t["trial"] < 0
    if d.seed is not None:
        cells = t[["instance", "stop", "trial"]].drop_duplicates()
        want = {(i, s, k): trial_seed(d.seed, int(i), s, int(k)) if s in STOPS else -1
                for i, s, k in cells.itertuples(index=False)}  # fmt: skip
        expected = [want[c] for c in zip(t["instance"], t["stop"], t["trial"])]
        yield (
            "seed is the protocol's paired seed of (seed, instance, stop, trial)",
            (t["seed"].to_numpy() != np.asarray(expected, dtype=np.int64)),
        )


def _instance_rules(t: pd.DataFrame, d: Design):
    inst = t["instance"].to_numpy()
    if d.names:
        yield "instance is one of the instances file's", ~np.isin(inst, list(d.names))
        yield (
            "map and map_set are the instance's",
            [d.names.get(int(i)) != (m, s) for i, m, s in zip(inst, t["map"], t["map_set"])],
        )
    if d.astar or d.exact:
        anyangle = (t["stop"] == "optimal_any_angle").to_numpy()
        ref = np.where(anyangle, _per(inst, d.exact), _per(inst, d.astar))
        known = ~np.isnan(ref)
        yield (
            "reference_length is the instance's optimum of the stop rule",
            known & ~np.isclose(t["reference_length"].to_numpy(), ref, rtol=1e-12, atol=0.0),
        )


def _per(inst: np.ndarray, values: dict[int, float]) -> np.ndarray:
    return np.array([values.get(int(i), math.nan) for i in inst], dtype=np.float64)


def _outcome_rules(t: pd.DataFrame, d: Design):
    cost, success = t["cost"].to_numpy(), t["success"].to_numpy()
    found = np.isfinite(cost)
    exact = _per(t["instance"].to_numpy(), d.exact)
    below = found & (cost < exact * (1.0 - COST_TOLERANCE))  # NaN exact: False
    yield f"cost >= the exact optimum (relative tolerance {COST_TOLERANCE:g})", below
    yield "cost is a length >= 0 or inf (no path)", ~(cost >= 0)
    yield "success exactly when stop_reason is solved", success != (t["stop_reason"] == "solved")
    yield "a success has a path (finite cost)", success & ~found
    optimal = t["stop"].isin(("optimal", "optimal_any_angle")).to_numpy()
    bound = (1.0 + d.eps) * t["reference_length"].to_numpy() * (1.0 + TARGET_TOLERANCE)
    yield (f"an optimal-stop success has cost <= (1 + eps) x reference_length (eps {d.eps:g})",
           success & optimal & ~(cost <= bound))  # fmt: skip
    it, tree = t["iterations"].to_numpy(), t["tree_size"].to_numpy()
    yield (
        f"iterations in 0..{d.max_iterations} (planner.max_iterations)",
        (it < 0) | (it > d.max_iterations),
    )
    yield "tree_size in 1..iterations + 2", (tree < 1) | (tree > it + 2)
    yield "collision_checks >= 0", t["collision_checks"].to_numpy() < 0


def _time_rules(t: pd.DataFrame):
    stop, setup = t["time_to_stop"].to_numpy(), t["setup_time"].to_numpy()
    first, found = t["time_to_first"].to_numpy(), np.isfinite(t["cost"].to_numpy())
    yield "time_to_stop is finite and >= 0", ~(np.isfinite(stop) & (stop >= 0))
    yield "setup_time is finite and >= 0", ~(np.isfinite(setup) & (setup >= 0))
    late = (t["stop_reason"] == "max_seconds").to_numpy()  # a path may come after the budget
    ok_first = np.isfinite(first) & (first >= 0) & (first <= stop + TIME_SLACK)
    yield ("time_to_first is in 0..time_to_stop when a path was found (within the time budget)",
           found & ~ok_first & ~(late & np.isnan(first)))  # fmt: skip
    yield "time_to_first is NaN when no path was found", ~found & ~np.isnan(first)
    for col in CONVERGENCE_COLUMNS:
        v = t[col].to_numpy()
        ok = np.isnan(v) | ((v >= 0) & (v <= stop + TIME_SLACK))
        yield f"{col} is NaN or in 0..time_to_stop", ~ok


def bundle_design(tables: dict[str, pd.DataFrame], optima: dict, eps: float,
                  max_iterations: int, seed: int) -> Design:  # fmt: skip
    """The :class:`Design` of a results bundle (:mod:`vnrrt.pipeline.recompute`), which
    keeps per map set the mean optima (``optima``: ``instances.json``), not each instance's:
    each instance's A* and exact optimum are its rows' references (``initial``/``optimal``
    and ``optimal_any_angle``), which must agree across rows and ``tables`` (``{name:
    table}``) and average to ``optima`` per map set (relative 1e-9);
    :class:`~vnrrt.evaluation.table.TableError` naming the table otherwise."""
    refs: dict[str, dict[int, float]] = {"astar": {}, "exact": {}}
    sets: dict[int, str] = {}
    for name, t in tables.items():
        kind = np.where(t["stop"] == "optimal_any_angle", "exact", "astar")
        for (k, i, m), ref in t.groupby([kind, "instance", "map_set"])["reference_length"]:
            values, known = ref.unique(), refs[k].get(int(i), ref.iloc[0])
            if len(values) > 1 or values[0] != known or sets.setdefault(int(i), m) != m:
                raise TableError(
                    f"trial table {name}: the rows of instance {i} do not agree on its {k} "
                    "reference_length or map set (edited or damaged)"
                )
            refs[k][int(i)] = float(values[0])
    for k, per in refs.items():
        for m, want in optima.items():
            got = [v for i, v in per.items() if sets[i] == m]
            if got and not math.isclose(float(np.mean(got)), want[k], rel_tol=1e-9):
                raise TableError(
                    f"trial tables {sorted(tables)}: the {k} references of map set {m} "
                    f"average {np.mean(got)!r}, not the instances' {want[k]!r}"
                )
    return Design(eps, max_iterations, seed, {}, refs["astar"], refs["exact"])
