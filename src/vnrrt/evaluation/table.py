"""The trial table: one row per planner run, its schema (:class:`TrialRow`, defined once),
and reading, merging and writing it.

Stage ``trials@<k>`` writes part ``k`` (``<trials dir>/part_<k>.csv``); stage ``evaluate``
merges the parts once, checks that they hold exactly rows ``0 .. N-1`` of the protocol, and
writes the merged table that the report and the statistics read.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from vnrrt.config.paths import table_part_file as part_file
from vnrrt.infra.io import DECODE_ERRORS, write_text

# Cost bounds (x reference length) whose first-reach time is recorded in optimal runs: the
# convergence curve (cost versus time) of every trial.
CONVERGENCE_FACTORS = (2.0, 1.5, 1.2, 1.1, 1.05, 1.02)


def convergence_column(factor: float) -> str:
    """Column of the time (s) to reach ``factor`` x reference length, e.g. ``t_1.05x``."""
    return f"t_{factor:g}x"


@dataclass(frozen=True)
class TrialRow:
    """One planner run. Lengths in pixels, times in seconds (planning only: building the
    sampler from the heatmap is per (instance, configuration) work, ``setup_time``; network
    inference is per map and reported separately)."""

    seq: int  # row number in the protocol's canonical order
    instance: int  # protocol instance index
    map_set: str  # map_1 .. map_5 | random
    map: str  # instance name
    cluster: int  # base map id: instances of one map are not independent
    key: str  # configuration key (planner, tau, source)
    planner: str  # rrt_star | nrrt_star | vnrrt_star | m_vnrrt_star
    tau: float  # mask threshold (NaN when unused)
    source: str  # heatmap source ('' for RRT*)
    stop: str  # initial | optimal | optimal_any_angle
    trial: int
    seed: int
    success: bool  # stop rule met within the budgets
    stop_reason: str  # solved | max_iterations | max_seconds (the time budget, after the run)
    fallback_uniform: bool  # the heatmap had no weight left (M-VNRRT* above tau): uniform
    reference_length: float  # A* length (initial, optimal) or exact optimum (optimal_any_angle)
    cost: float  # length of the best path found (inf: none)
    iterations: int  # samples drawn
    tree_size: int
    collision_checks: int
    time_to_first: float  # s to the first solution (NaN: none)
    time_to_stop: float  # s until the stop rule or a budget
    setup_time: float  # s to build the sampler of this (instance, configuration), once
    convergence: tuple[float, ...] = ()  # s to CONVERGENCE_FACTORS x reference (optimal)
    regime: str = ""  # planner settings of a regime-sweep cell ('' = the protocol's)
    heat_mass: float = math.nan  # share of the heatmap's mass within r px of its target
    uniform_mass: float = math.nan  # the same share of a uniform map (over the allowed cells)
    # where the sampler's heatmap weights lie (after M-VNRRT*'s mask; vnrrt.evaluation.sources)
    mass_endpoints: float = math.nan  # on the start/goal disks
    mass_interior: float = math.nan  # near the interior vertices
    mass_path: float = math.nan  # near the rest of the path
    # the machine's timing noise: the same run timed again later in the stage (same seed,
    # same iterations; eval.timing_noise, protocol RRT* only; NaN where not repeated)
    time_to_first_repeat: float = math.nan
    time_to_stop_repeat: float = math.nan
    # the training seed (train.seed) of the network whose heatmap the sampler draws from; -1:
    # none (RRT*, oracles), a network trained elsewhere, or a table written before the column
    network_seed: int = -1
    # how the run itself stopped (its wall-clock cap eval.cap_factor x the time budget, which
    # ``stop_reason`` applies after the run): what the iteration readings see (:func:`solved`);
    # '' in a table written before the column: read as ``stop_reason``
    run_stop_reason: str = ""

    def record(self) -> dict:
        """The row as ``{column: value}`` (convergence times as ``t_<f>x`` columns)."""
        out = {f.name: getattr(self, f.name) for f in FIELDS}
        times = self.convergence or (math.nan,) * len(CONVERGENCE_FACTORS)
        out.update(zip(CONVERGENCE_COLUMNS, times, strict=True))
        return out


FIELDS = tuple(f for f in dataclasses.fields(TrialRow) if f.name != "convergence")
CONVERGENCE_COLUMNS = tuple(convergence_column(f) for f in CONVERGENCE_FACTORS)
COLUMNS = tuple(f.name for f in FIELDS) + CONVERGENCE_COLUMNS
# Columns that measure time, and so change from run to run; every other column depends on
# the inputs and seeds only (a re-run, or another split into parts, reproduces it exactly).
REPEAT_COLUMNS = ("time_to_first_repeat", "time_to_stop_repeat")
TIMING_COLUMNS = ("time_to_first", "time_to_stop", "setup_time", *CONVERGENCE_COLUMNS,
                  *REPEAT_COLUMNS)  # fmt: skip
SEEDED_COLUMNS = tuple(c for c in COLUMNS if c not in TIMING_COLUMNS)
_KINDS = {int: "int64", float: "float64", str: "object", bool: "bool"}
DTYPES = {
    f.name: _KINDS[{"int": int, "float": float, "str": str, "bool": bool}[f.type]] for f in FIELDS
} | dict.fromkeys(CONVERGENCE_COLUMNS, "float64")


class TableError(ValueError):
    """A trial table is missing, incomplete or of another schema; the message names it."""


def frame(rows: list[TrialRow]) -> pd.DataFrame:
    """Rows as a table with the columns :data:`COLUMNS`, sorted by ``seq``."""
    table = pd.DataFrame([r.record() for r in rows], columns=list(COLUMNS))
    return conform(table, "rows").sort_values("seq", kind="stable", ignore_index=True)


def conform(table: pd.DataFrame, where: str) -> pd.DataFrame:
    """``table`` with exactly :data:`COLUMNS` in order and their dtypes; :class:`TableError`
    naming ``where`` if a column is missing (the :data:`REPEAT_COLUMNS`, absent from tables
    written before they existed, read as NaN: not repeated; ``network_seed`` as -1;
    ``run_stop_reason`` as ``stop_reason``: the run stopped at the time budget)."""
    table = table.assign(**{c: math.nan for c in REPEAT_COLUMNS if c not in table.columns})
    seeds = table["network_seed"] if "network_seed" in table.columns else -1
    table = table.assign(network_seed=pd.Series(seeds, index=table.index).fillna(-1))
    if "stop_reason" in table.columns:  # run_stop_reason absent or '': the stop_reason
        run = table["run_stop_reason"] if "run_stop_reason" in table.columns else ""
        run = pd.Series(run, index=table.index, dtype=object).fillna("").astype(str)
        table = table.assign(run_stop_reason=run.where(run != "", table["stop_reason"]))
    missing = [c for c in COLUMNS if c not in table.columns]
    if missing:
        raise TableError(f"trial table {where} lacks columns {missing} (re-run the trials)")
    out = table[list(COLUMNS)].copy()
    for col, dtype in DTYPES.items():
        if dtype == "object":
            out[col] = out[col].fillna("").astype(str)
        else:
            out[col] = out[col].astype(dtype)
    return out


def solved(table: pd.DataFrame, metric: str) -> pd.Series:
    """Which runs of ``table`` met the stop rule within the budget that bounds ``metric``'s
    reading: for ``iterations`` the iteration budget (the run's own stop, ``run_stop_reason``:
    a time budget applied after the run does not cut its iterations), for every other metric
    both budgets (``success``; also where a table has no ``run_stop_reason``)."""
    if metric == "iterations" and "run_stop_reason" in table.columns:
        return table["run_stop_reason"] == "solved"
    return table["success"]


def with_network_seeds(table: pd.DataFrame, seeds: dict[str, int]) -> pd.DataFrame:
    """``table`` with ``network_seed`` set from ``seeds`` (heatmap source -> the training
    seed of the network that made it) and -1 for every other source."""
    mapped = table["source"].map({str(k): int(v) for k, v in seeds.items()})
    return table.assign(network_seed=mapped.fillna(-1).astype("int64"))


def write_table(table: pd.DataFrame, path: str | Path) -> None:
    """Write a trial table as CSV, atomically (floats as Python writes them: round trips)."""
    write_text(path, conform(table, str(path)).to_csv(index=False, na_rep="nan"))


def read_table(path: str | Path) -> pd.DataFrame:
    """A trial table written by :func:`write_table`; :class:`TableError` naming the file."""
    path = Path(path)
    if not path.is_file():
        raise TableError(f"trial table {path} does not exist (run `dvc repro`)")
    dtypes = {c: ("str" if d == "object" else d) for c, d in DTYPES.items() if d != "bool"}
    floats = {c: ["nan"] for c, d in DTYPES.items() if d == "float64"}
    try:
        table = pd.read_csv(path, dtype=dtypes, keep_default_na=False, na_values=floats)
    except (*DECODE_ERRORS, pd.errors.ParserError) as err:  # cut, damaged, not a table
        why = " ".join(str(err).split()) or type(err).__name__
        raise TableError(f"trial table {path} is unreadable: {why}") from None
    for col in ("success", "fallback_uniform"):
        if col in table and table[col].dtype != bool:
            table[col] = table[col].astype(str).str.lower() == "true"
    return conform(table, str(path))


def merge_parts(
    directory: str | Path, parts: list[int], expected: int, design=None
) -> pd.DataFrame:
    """The tables of ``parts`` merged in ``seq`` order. :class:`TableError` naming the missing
    files, or the directory unless the rows are exactly ``seq`` 0 .. expected-1, or a part
    and its row that breaks a rule of ``design`` (a
    :class:`vnrrt.evaluation.invariants.Design`; None: unchecked)."""
    missing = [str(part_file(directory, k)) for k in parts if not part_file(directory, k).is_file()]
    if missing:
        raise TableError(f"trial tables {missing} do not exist (run `dvc repro`)")
    tables = [read_table(part_file(directory, k)) for k in parts]
    if design is not None:
        for k, table in zip(parts, tables, strict=True):
            design.check(table, str(part_file(directory, k)))
    table = pd.concat(tables, ignore_index=True).sort_values("seq", kind="stable")
    if not np.array_equal(table["seq"].to_numpy(), np.arange(expected)):
        raise TableError(
            f"trial tables in {directory} (parts {list(parts)}) do not hold rows "
            f"0..{expected - 1} of this protocol: a part is missing, repeated or from "
            f"another config (re-run `dvc repro`)"
        )
    return table.reset_index(drop=True)
