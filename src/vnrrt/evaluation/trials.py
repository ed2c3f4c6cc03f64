"""Run the protocol's trial jobs (:mod:`vnrrt.evaluation.protocol`) over all cores; one
:class:`~vnrrt.evaluation.table.TrialRow` per planner run.

Per job (one instance, one configuration, one stop rule, up to 25 trials) the sampler is
built once from the instance's heatmap, outside the timed region, and every trial plans
with it; its build time is recorded as ``setup_time``. Trial ``t`` of an instance gets the
same seed in every configuration (:func:`vnrrt.evaluation.protocol.trial_seed`).
"""

from __future__ import annotations

import dataclasses
import functools
import math
import time

import pandas as pd

from vnrrt.evaluation.instances import EvalInstance
from vnrrt.evaluation.protocol import PlannerSpec, TrialJob, trial_jobs, trial_seed
from vnrrt.evaluation.table import CONVERGENCE_FACTORS, TrialRow, frame
from vnrrt.parallel import parallel_map
from vnrrt.planners import PlannerConfig, make_sampler, plan, warmup


def _row(
    job: TrialJob, inst: EvalInstance, trial: int, seed: int, result, setup: float, ref: float
) -> TrialRow:
    spec = job.spec
    return TrialRow(
        seq=job.seq + trial - job.first,
        instance=job.instance,
        map_set=inst.map_set,
        map=inst.map,
        cluster=inst.cluster,
        key=spec.key,
        planner=spec.planner,
        tau=math.nan if spec.tau is None else float(spec.tau),
        source=spec.source or "",
        stop=job.stop,
        trial=trial,
        seed=seed,
        success=result.success,
        stop_reason=result.stop_reason,
        fallback_uniform=result.fallback_uniform,
        reference_length=ref,
        cost=result.cost,
        iterations=result.iterations,
        tree_size=result.tree_size,
        collision_checks=result.collision_checks,
        time_to_first=result.time_to_first,
        time_to_stop=result.time_to_stop,
        setup_time=setup,
        convergence=tuple(m.time for m in result.milestones),
    )


def run_job(args: tuple[TrialJob, EvalInstance], seed: int, config: PlannerConfig) -> list:
    """The rows of one job on its instance (``args``: the job and its instance)."""
    job, inst = args
    spec, stop = job.spec, job.stop
    warmup()
    heatmap = None if spec.source is None else inst.heatmaps[spec.source]
    tick = time.perf_counter()
    sampler = make_sampler(spec.planner, inst.grid.shape, heatmap, spec.tau, config.mix)
    setup = time.perf_counter() - tick
    ref = inst.reference(stop)
    milestones = tuple(f * ref for f in CONVERGENCE_FACTORS) if stop != "initial" else ()
    rows = []
    for trial in range(job.first, job.first + job.count):
        s = trial_seed(seed, job.instance, stop, trial)
        r = plan(
            inst.grid,
            inst.start,
            inst.goal,
            spec.planner,
            sampler=sampler,
            stop="initial" if stop == "initial" else "optimal",
            reference_length=ref,
            seed=s,
            milestones=milestones,
            config=config,
        )
        rows.append(_row(job, inst, trial, s, r, setup, ref))
    return rows


def _needed(job: TrialJob, inst: EvalInstance) -> tuple[TrialJob, EvalInstance]:
    """The job with an instance holding only the heatmap it samples (less to pickle)."""
    src = job.spec.source
    if src is not None and src not in inst.heatmaps:
        raise KeyError(
            f"instance {inst.map} has no {src!r} heatmap (known: {sorted(inst.heatmaps)})"
        )
    keep = {} if src is None else {src: inst.heatmaps[src]}
    return job, dataclasses.replace(inst, heatmaps=keep)


def run_jobs(
    jobs: list[TrialJob],
    instances: dict[int, EvalInstance],
    seed: int = 0,
    workers: int = 0,
    config: PlannerConfig | None = None,
) -> pd.DataFrame:
    """The rows of ``jobs`` (on ``instances[job.instance]``) as a trial table in ``seq``
    order. A trial that exhausts a budget is a row with ``success=False``."""
    fn = functools.partial(run_job, seed=seed, config=config or PlannerConfig())
    items = [_needed(job, instances[job.instance]) for job in jobs]
    rows = parallel_map(fn, items, workers, "trials")
    return frame([r for rs in rows for r in rs])


def run_trials(
    instances: list[EvalInstance],
    specs: list[PlannerSpec],
    counts: dict[tuple[str, str], int],
    seed: int = 0,
    workers: int = 0,
    config: PlannerConfig | None = None,
) -> pd.DataFrame:
    """All trials of ``specs`` on ``instances`` (protocol order) as a table;
    ``counts[(kind, stop)]`` trials per instance, kind ``'named'`` or ``'random'``."""
    jobs = trial_jobs([inst.kind for inst in instances], specs, counts)
    by_index = {i: inst for i, inst in enumerate(instances)}
    return run_jobs(jobs, by_index, seed, workers, config)
