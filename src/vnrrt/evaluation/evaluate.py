"""The ``evaluate`` stage: the paper's protocol over the named and random test maps, the
per-trial table, summary metrics (``dvc metrics``) and curves (``dvc plots``).

Planner configurations come from ``eval.planners``; M-VNRRT* runs once per threshold in
``planner.taus`` plus ``planner.tau`` (so ``dvc exp run -S planner.tau=0.7`` adds one).
Trial counts and the number of random maps come from the ``eval`` section (set per scale).

The trials are split into the parts of ``eval.parts`` (:func:`vnrrt.evaluation.trials.part_jobs`)
so that they can run as shard jobs (:mod:`vnrrt.multirun`) as well as DVC stages: part ``k``
writes ``<paths.trials>/part_<k>.csv`` (stage ``trials@<k>``) and stage ``evaluate`` merges
the parts back into the protocol's table, row ``seq`` at row ``seq``, whatever the split.
"""

from __future__ import annotations

import dataclasses
import logging
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd

from vnrrt.config import ConfigError, check_parts
from vnrrt.evaluation.instances import instance_kinds, load_eval_instances
from vnrrt.evaluation.report import check_trials
from vnrrt.evaluation.stats import summarize
from vnrrt.evaluation.trials import (
    CONVERGENCE_FACTORS,
    PlannerSpec,
    convergence_column,
    part_jobs,
    run_jobs,
    trial_jobs,
)
from vnrrt.planners import PlannerConfig
from vnrrt.planners.reference import any_angle_length

log = logging.getLogger(__name__)


DEFAULT_NETWORKS = {"nrrt_star": "nrrtnet", "vnrrt_star": "vertexnet", "m_vnrrt_star": "vertexnet"}


@dataclass
class EvalConfig:
    """The evaluation protocol (paper, Experiments). Trial counts are per instance."""

    planners: list[str] = field(
        default_factory=lambda: ["rrt_star", "nrrt_star", "vnrrt_star", "m_vnrrt_star"]
    )
    # planner -> network whose heatmap it samples (networks.<name>.target: vertex | path)
    networks: dict[str, str] = field(default_factory=lambda: dict(DEFAULT_NETWORKS))
    named_initial: int = 1000  # paper: 1,000 trials per named map
    named_optimal: int = 100  # paper: 100
    random_maps: int = 1000  # paper: 1,000 test maps, one trial each
    random_initial: int = 1
    random_optimal: int = 1
    # also run the optimal trials to within 1 + eps of the any-angle length (stricter than
    # the paper's A* reference; reported in an extra table)
    any_angle: bool = True
    parts: list[int] = field(default_factory=lambda: [0])  # trial parts: [0, 1, ..., K-1]

    def validate(self) -> None:
        check_parts(self.parts, "eval.parts")
        for name in ("named_initial", "named_optimal", "random_maps", "random_initial",
                     "random_optimal"):  # fmt: skip
            if getattr(self, name) < 0:
                raise ConfigError(f"invalid config value eval.{name}: must be >= 0")
        for p in self.planners:
            if p != "rrt_star" and p not in self.networks:
                raise ConfigError(f"eval.networks has no network for planner {p!r}")


def planner_specs(ev: EvalConfig, planner: PlannerConfig, targets: dict[str, str]) -> list:
    """The evaluated configurations; ``targets`` maps a network to its heatmap source."""
    specs = []
    for p in ev.planners:
        source = None if p == "rrt_star" else targets[ev.networks[p]]
        if p == "m_vnrrt_star":
            for tau in sorted({*planner.taus, planner.tau}):
                specs.append(PlannerSpec(p, float(tau), source))
        else:
            specs.append(PlannerSpec(p, None, source))
    return specs


def trial_counts(ev: EvalConfig) -> dict[tuple[str, str], int]:
    """Trials per instance for each (map kind, stop rule)."""
    strict = {}
    if ev.any_angle:
        strict = {("named", "optimal_any_angle"): ev.named_optimal,
                  ("random", "optimal_any_angle"): ev.random_optimal}  # fmt: skip
    return {
        ("named", "initial"): ev.named_initial,
        ("named", "optimal"): ev.named_optimal,
        ("random", "initial"): ev.random_initial,
        ("random", "optimal"): ev.random_optimal,
        **strict,
    }


def with_references(instances: list, reference: str) -> list:
    """Add each instance's any-angle length; make it the reference of the ``optimal`` stop
    too when ``planner.reference`` is ``any_angle``."""
    out = []
    for inst in instances:
        taut = any_angle_length(inst.grid, inst.start, inst.goal)
        ref = taut if reference == "any_angle" else inst.reference_length
        out.append(dataclasses.replace(inst, reference_length=ref, any_angle_length=taut))
    return out


def summary_metrics(trials: pd.DataFrame) -> dict:
    """``{stop: {planner key: {map_set: {success_rate, time_mean, time_median,
    iterations_median, cost_mean}}}}`` for ``dvc metrics show``."""
    out: dict = {}
    for (stop, key, map_set), sub in check_trials(trials).groupby(["stop", "key", "map_set"]):
        t = summarize(sub["time_to_stop"].to_numpy(), sub["success"].to_numpy(), n_boot=200)
        it = summarize(sub["iterations"].to_numpy(), sub["success"].to_numpy(), n_boot=200)
        out.setdefault(stop, {}).setdefault(key, {})[map_set] = {
            "success_rate": round(t.success_rate, 4),
            "time_mean": t.mean, "time_median": t.median,
            "iterations_median": it.median,
            "cost_mean": float(sub.loc[sub["success"], "cost"].mean()),
        }  # fmt: skip
    return out


def convergence_curves(trials: pd.DataFrame, eps: float) -> pd.DataFrame:
    """Median time (s) to reach each cost factor x reference, per planner key and map set
    (successful optimal runs; the last point, factor ``1 + eps``, is the stop rule)."""
    opt = check_trials(trials)
    opt = opt[(opt["stop"] == "optimal") & opt["success"]]
    rows = []
    cols = [convergence_column(f) for f in CONVERGENCE_FACTORS]
    for (key, map_set), sub in opt.groupby(["key", "map_set"]):
        for f, col in zip(CONVERGENCE_FACTORS, cols):
            rows.append({"planner": key, "map_set": map_set, "factor": f,
                         "median_time": float(np.median(sub[col]))})  # fmt: skip
        rows.append({"planner": key, "map_set": map_set, "factor": 1.0 + eps,
                     "median_time": float(np.median(sub["time_to_stop"]))})  # fmt: skip
    return pd.DataFrame(rows)


def protocol_jobs(instances_args: dict, ev: EvalConfig, planner: PlannerConfig,
                  targets: dict[str, str]) -> list:  # fmt: skip
    """Every :class:`~vnrrt.evaluation.trials.TrialJob` of the protocol, in canonical order;
    ``instances_args`` are :func:`load_eval_instances` arguments."""
    kinds = instance_kinds(instances_args["named_maps"], instances_args["n_random"])
    return trial_jobs(kinds, planner_specs(ev, planner, targets), trial_counts(ev))


def evaluate_part(instances_args: dict, ev: EvalConfig, planner: PlannerConfig,
                  targets: dict[str, str], seed: int, workers: int,
                  part: int = 0) -> pd.DataFrame:  # fmt: skip
    """The trials of part ``part`` of ``ev.parts`` (all of them with one part)."""
    jobs = part_jobs(protocol_jobs(instances_args, ev, planner, targets), part, len(ev.parts))
    needed = {job.instance for job in jobs}
    loaded = load_eval_instances(**instances_args, only=needed)
    instances = dict(zip(loaded, with_references(list(loaded.values()), planner.reference)))
    log.info("part %d/%d: %d trial jobs on %d instances", part, len(ev.parts), len(jobs),
             len(instances))  # fmt: skip
    return run_jobs(jobs, instances, seed, workers, planner)


def trials_file(directory: str | Path, part: int) -> Path:
    """``<directory>/part_<part>.csv``: the trial table of part ``part``."""
    return Path(directory) / f"part_{part}.csv"


def read_trials(
    directory: str | Path, parts: list[int], expected: int | None = None
) -> pd.DataFrame:
    """The trial tables of ``parts`` merged in ``seq`` order. ``FileNotFoundError`` naming
    the missing parts, ``ValueError`` naming the directory unless the rows are exactly
    ``seq`` 0 .. N-1 (``N = expected`` if given)."""
    missing = [
        str(trials_file(directory, k)) for k in parts if not trials_file(directory, k).is_file()
    ]
    if missing:
        raise FileNotFoundError(f"trial tables {missing} do not exist (run `dvc repro evaluate`)")
    tables = [pd.read_csv(trials_file(directory, k)) for k in parts]
    table = pd.concat(tables, ignore_index=True).sort_values(
        "seq", kind="stable", ignore_index=True
    )
    n = len(table) if expected is None else expected
    if not np.array_equal(table["seq"].to_numpy(), np.arange(n)):
        raise ValueError(f"trial tables in {directory} (parts {list(parts)}) do not hold rows "
                         f"0..{n - 1} of one protocol: a part is missing, repeated or from "
                         f"another config (re-run `dvc repro evaluate`)")  # fmt: skip
    return table


def write_table(table: pd.DataFrame, path: str | Path) -> None:
    """CSV, atomically."""
    from vnrrt.data.shards import atomic_write_bytes

    atomic_write_bytes(Path(path), lambda f: f.write(table.to_csv(index=False).encode()))
