"""Run trial jobs (:mod:`vnrrt.evaluation.protocol`) over all cores; one
:class:`~vnrrt.evaluation.table.TrialRow` per planner run.

Per job (one instance, one configuration, one stop rule, up to 25 trials) the heatmap is
looked up (a trained network's, read from the prediction files) or built (an oracle,
:mod:`vnrrt.evaluation.oracle`, from the instance's labels), the sampler is built from it
once, outside the timed region, and every trial plans with it; the build time is recorded
as ``setup_time`` and the heatmap's mass near its target as ``heat_mass``. Trial ``t`` of an
instance gets the same seed in every configuration
(:func:`vnrrt.evaluation.protocol.trial_seed`).
"""

from __future__ import annotations

import dataclasses
import functools
import math
import time
from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from vnrrt.evaluation import oracle
from vnrrt.evaluation.instances import EvalInstance
from vnrrt.evaluation.protocol import PlannerSpec, TrialJob, trial_jobs, trial_seed
from vnrrt.evaluation.table import CONVERGENCE_FACTORS, TrialRow, frame
from vnrrt.parallel import parallel_map
from vnrrt.planners import PlannerConfig, make_sampler, plan, warmup


@dataclass(frozen=True)
class HeatSettings:
    """How oracle heatmaps are built and heatmaps measured: blur ``sigma`` and ``floor`` of
    the oracles, ``radius`` (px) of "mass near the target", and the target of each trained
    network (``'path'`` or ``'interior_vertices'``)."""

    sigma: float = 1.0
    floor: float = 0.0
    radius: float = 3.0
    targets: dict[str, str] = field(default_factory=dict)


def source_heatmap(source: str, inst: EvalInstance, heat: HeatSettings) -> np.ndarray:
    """The heatmap a job samples: a network's (on the instance) or an oracle's (built)."""
    if source in inst.heatmaps:
        return inst.heatmaps[source]
    if source.startswith("oracle_"):
        return oracle.instance_heatmap(source, inst, heat.sigma, heat.floor)
    known = sorted(inst.heatmaps)
    raise KeyError(f"instance {inst.map} has no {source!r} heatmap (known: {known})")


def source_target(source: str, heat: HeatSettings) -> str:
    """The target a source's heatmap aims at (for ``heat_mass``)."""
    if source.startswith("oracle_"):
        return oracle.TARGET[oracle.parse_source(source)[0]]
    return heat.targets.get(source, "path")


def _row(job, inst, trial, seed, result, setup, ref, mass) -> TrialRow:
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
        regime=job.regime,
        heat_mass=mass,
    )


def run_job(
    args: tuple[TrialJob, EvalInstance],
    seed: int,
    configs: dict[str, PlannerConfig],
    heat: HeatSettings,
) -> list[TrialRow]:
    """The rows of one job on its instance (``args``: the job and its instance);
    ``configs`` holds the planner settings of each regime cell (``''``: the protocol's)."""
    job, inst = args
    spec, stop, config = job.spec, job.stop, configs[job.regime]
    if spec.informed:
        config = config.replace(informed=True)
    if spec.tau is not None:
        config = config.replace(tau=spec.tau)
    warmup()
    heatmap, mass = None, math.nan
    if spec.source is not None:
        heatmap = source_heatmap(spec.source, inst, heat)
        mask = oracle.target_mask(inst, source_target(spec.source, heat))
        mass = oracle.mass_near(heatmap, mask, heat.radius)
    tick = time.perf_counter()
    sampler = make_sampler(spec.planner, inst.grid.shape, heatmap, config)
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
        rows.append(_row(job, inst, trial, s, r, setup, ref, mass))
    return rows


def _needed(job: TrialJob, inst: EvalInstance) -> tuple[TrialJob, EvalInstance]:
    """The job with an instance holding only the heatmap it samples (less to pickle)."""
    src = job.spec.source
    if src is not None and not src.startswith("oracle_") and src not in inst.heatmaps:
        known = sorted(inst.heatmaps)
        raise KeyError(f"instance {inst.map} has no {src!r} heatmap (known: {known})")
    keep = {src: inst.heatmaps[src]} if src in inst.heatmaps else {}
    return job, dataclasses.replace(inst, heatmaps=keep)


def run_jobs(
    jobs: list[TrialJob],
    instances: dict[int, EvalInstance],
    seed: int = 0,
    workers: int = 0,
    config: PlannerConfig | dict[str, PlannerConfig] | None = None,
    heat: HeatSettings | None = None,
) -> pd.DataFrame:
    """The rows of ``jobs`` (on ``instances[job.instance]``) as a trial table in ``seq``
    order. ``config``: the planner settings, or one per regime cell. A trial that exhausts
    a budget is a row with ``success=False``."""
    configs = config if isinstance(config, dict) else {"": config or PlannerConfig()}
    fn = functools.partial(run_job, seed=seed, configs=configs, heat=heat or HeatSettings())
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
    heat: HeatSettings | None = None,
) -> pd.DataFrame:
    """All trials of ``specs`` on ``instances`` (protocol order) as a table;
    ``counts[(kind, stop)]`` trials per instance, kind ``'named'`` or ``'random'``."""
    jobs = trial_jobs([inst.kind for inst in instances], specs, counts)
    by_index = dict(enumerate(instances))
    return run_jobs(jobs, by_index, seed, workers, config, heat)
