"""Planner trials of the paper's protocol: every planner configuration, on every evaluation
instance, for N trials per stop rule, over all cores; one table row per trial.

An :class:`EvalInstance` carries its own grid, continuous start/goal (cell centres), A*
reference length and the heatmaps the learned planners sample from (``'path'``: the
NRRT* network, ``'vertex'``: VertexNet), so jobs are self-contained and picklable.
Seeds derive from (global seed, instance index, planner configuration, stop, trial) only:
the table does not depend on the number of workers or the order of jobs.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from vnrrt.evaluation.report import TRIAL_COLUMNS, planner_key
from vnrrt.parallel import parallel_map
from vnrrt.planners import PlannerConfig, plan, warmup

# Stop rules of the protocol: the paper's two, and the stricter any-angle optimum.
STOPS = ("initial", "optimal", "optimal_any_angle")

# Cost bounds (x reference length) whose first-reach time is recorded in optimal runs:
# the convergence curve (cost versus time) of every trial.
CONVERGENCE_FACTORS = (2.0, 1.5, 1.2, 1.1, 1.05, 1.02)


def convergence_column(factor: float) -> str:
    """Column of the time (s) to reach ``factor`` x reference length, e.g. ``t_1.05x``."""
    return f"t_{factor:g}x"


@dataclass(frozen=True)
class PlannerSpec:
    """One evaluated configuration: a planner, its mask threshold and heatmap source."""

    planner: str
    tau: float | None = None
    heatmap: str | None = None  # key into EvalInstance.heatmaps; None = uniform

    @property
    def key(self) -> str:
        return planner_key(self.planner, self.tau)


@dataclass(frozen=True)
class EvalInstance:
    """One planning problem: ``grid`` (H, W) uint8, ``start``/``goal`` (x, y) pixels,
    ``reference_length`` (A* optimum, px), ``heatmaps`` name -> (H, W) float array and,
    for the ``optimal_any_angle`` stop, the any-angle length (px)."""

    map_set: str  # map_1 .. map_5 | random
    map: str
    grid: np.ndarray
    start: tuple[float, float]
    goal: tuple[float, float]
    reference_length: float
    heatmaps: dict[str, np.ndarray] = field(default_factory=dict)
    any_angle_length: float | None = None  # the taut A* path's length, for optimal_any_angle


def trial_seed(seed: int, instance: int, spec: PlannerSpec, stop: str, trial: int) -> int:
    """A 63-bit seed from (global seed, instance, planner configuration, stop, trial)."""
    key = [ord(c) for c in f"{spec.key}/{stop}"]
    ss = np.random.SeedSequence([seed, instance, trial, *key])
    return int(ss.generate_state(1, np.uint64)[0] >> np.uint64(1))


# Trials of one (instance, configuration, stop) are cut into jobs of at most this many, so
# that a process pool and the parts of ``eval.parts`` share the work evenly.
TRIALS_PER_JOB = 25


@dataclass(frozen=True)
class TrialJob:
    """Trials ``first .. first + count - 1`` of one (instance, configuration, stop); their
    rows are ``seq .. seq + count - 1`` of the whole protocol's table (canonical order:
    instance, configuration, stop, trial)."""

    instance: int
    spec: PlannerSpec
    stop: str
    first: int
    count: int
    seq: int


def trial_jobs(kinds: list[str], specs: list[PlannerSpec], trials: dict[tuple[str, str], int],
               per_job: int = TRIALS_PER_JOB) -> list[TrialJob]:  # fmt: skip
    """Every job of the protocol, in canonical order; ``kinds[i]`` is ``'named'`` or
    ``'random'`` for evaluation instance ``i`` and ``trials`` as in :func:`run_trials`."""
    jobs, seq = [], 0
    for i, kind in enumerate(kinds):
        for spec in specs:
            for stop in STOPS:
                n = trials.get((kind, stop), 0)
                for first in range(0, n, per_job):
                    count = min(per_job, n - first)
                    jobs.append(TrialJob(i, spec, stop, first, count, seq))
                    seq += count
    return jobs


def part_jobs(jobs: list[TrialJob], part: int, parts: int) -> list[TrialJob]:
    """The jobs of part ``part`` of ``parts``: every ``parts``-th job (round robin, so each
    part gets a similar mix of named and random maps, configurations and stop rules)."""
    if not 0 <= part < parts:
        raise ValueError(f"part {part} is not in 0..{parts - 1}")
    return jobs[part::parts]


def _job(args, seed: int, config: PlannerConfig) -> list[dict]:
    """Run the trials of one :class:`TrialJob` on its instance; returns table rows."""
    job, inst = args
    spec, stop = job.spec, job.stop
    warmup()
    heatmap = None if spec.heatmap is None else inst.heatmaps[spec.heatmap]
    factors = CONVERGENCE_FACTORS if stop == "optimal" else ()
    ref = inst.any_angle_length if stop == "optimal_any_angle" else inst.reference_length
    rows = []
    for trial in range(job.first, job.first + job.count):
        r = plan(
            inst.grid, inst.start, inst.goal, spec.planner, heatmap=heatmap, tau=spec.tau,
            stop="initial" if stop == "initial" else "optimal", reference_length=ref,
            seed=trial_seed(seed, job.instance, spec, stop, trial),
            milestones=tuple(f * inst.reference_length for f in factors), config=config,
        )  # fmt: skip
        rows.append({
            "planner": spec.planner, "tau": np.nan if spec.tau is None else spec.tau,
            "map_set": inst.map_set, "map": inst.map, "trial": trial, "stop": stop,
            "success": r.success, "cost": r.cost, "iterations": r.iterations,
            "tree_size": r.tree_size, "collision_checks": r.collision_checks,
            "time_to_first": r.time_to_first, "time_to_stop": r.time_to_stop,
            "stop_reason": r.stop_reason, "reference_length": ref,
            "fallback_uniform": r.fallback_uniform, "instance": job.instance,
            "seq": job.seq + trial - job.first,
            **{convergence_column(f): m.time for f, m in zip(factors, r.milestones)},
        })  # fmt: skip
    return rows


def run_jobs(jobs: list[TrialJob], instances: dict[int, EvalInstance], seed: int = 0,
             workers: int = 0, config: PlannerConfig | None = None) -> pd.DataFrame:  # fmt: skip
    """The rows of ``jobs`` (on ``instances[job.instance]``) as a table in ``seq`` order
    (columns :data:`TRIAL_COLUMNS` and a few more). A trial that exhausts a budget is a row
    with ``success=False``; ``config`` holds the planner settings of
    :func:`vnrrt.planners.plan`."""
    for job in jobs:
        inst = instances[job.instance]
        if job.spec.heatmap is not None and job.spec.heatmap not in inst.heatmaps:
            raise KeyError(f"instance {inst.map} has no '{job.spec.heatmap}' heatmap")
        if job.stop == "optimal_any_angle" and inst.any_angle_length is None:
            raise ValueError(f"instance {inst.map} has no any-angle length")
    fn = functools.partial(_job, seed=seed, config=config or PlannerConfig())
    parts = parallel_map(fn, [(job, instances[job.instance]) for job in jobs], workers, "trials")
    table = pd.DataFrame([row for rows in parts for row in rows])
    extra = [c for c in table if c not in TRIAL_COLUMNS]
    extra += [c for c in ("instance", "seq") if c not in extra]  # also in an empty table
    table = table.reindex(columns=[*TRIAL_COLUMNS, *extra])
    return table.sort_values("seq", kind="stable", ignore_index=True)


def run_trials(
    instances: list[EvalInstance],
    specs: list[PlannerSpec],
    trials: dict[tuple[str, str], int],
    seed: int = 0,
    workers: int = 0,
    config: PlannerConfig | None = None,
) -> pd.DataFrame:
    """All trials as a table (:func:`run_jobs`).

    ``trials[(map_set_kind, stop)]`` is the number of trials per instance, with
    ``map_set_kind`` ``'named'`` (map_1 .. map_5) or ``'random'``.
    """
    kinds = ["random" if inst.map_set == "random" else "named" for inst in instances]
    jobs = trial_jobs(kinds, specs, trials)
    return run_jobs(jobs, dict(enumerate(instances)), seed, workers, config)
