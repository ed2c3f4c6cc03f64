"""Run trial jobs (:mod:`vnrrt.evaluation.protocol`) over all cores; one
:class:`~vnrrt.evaluation.table.TrialRow` per planner run.

Per job (one instance, one configuration, one stop rule, up to 25 trials) the heatmap is
looked up (a trained network's, read from the prediction files) or built (an oracle,
:mod:`vnrrt.evaluation.sources`, from the instance's labels), the sampler is built from it
once, outside the timed region, and every trial plans with it; the build time is recorded
as ``setup_time`` and the heatmap's mass near its target as ``heat_mass``. Trial ``t`` of an
instance gets the same seed in every configuration
(:func:`vnrrt.evaluation.protocol.trial_seed`).
"""

from __future__ import annotations

import dataclasses
import functools
import logging
import math
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from vnrrt.data.heatmaps import HeatmapError
from vnrrt.data.instances import EvalInstance
from vnrrt.evaluation import reuse, sources
from vnrrt.evaluation.keys import ConfigKey
from vnrrt.evaluation.protocol import TrialJob, timed_twice, trial_jobs, trial_seed
from vnrrt.evaluation.sampling import build_sampler, free_rule
from vnrrt.evaluation.table import CONVERGENCE_FACTORS, TrialRow, conform, frame
from vnrrt.infra.parallel import parallel_map
from vnrrt.planners import PlannerConfig, PlanResult, plan, warmup

log = logging.getLogger(__name__)


@dataclass(frozen=True)
class TrialSettings:
    """How a stage's trials run, beside the planner settings: how heatmaps are measured and
    oracle heatmaps built (``radius`` (px) of "mass near the target", ``oracle.radius``; the
    start/goal disks' ``endpoint_radius`` (px, ``eval.endpoint_radius``: the ``noends`` mask
    and the mass shares); the target of each trained network (``'path'`` or
    ``'interior_vertices'``); the oracles' blur ``sigma`` (px) and uniform ``floor``
    (``oracle.sigma``, ``oracle.floor``; None where a stage samples no oracle)), the default
    obstacle rule (``eval.zero_obstacles``; a key's ``+free`` flips it:
    :mod:`vnrrt.evaluation.sampling`) and each run's wall-clock cap, ``cap_factor`` x the
    time budget (``eval.cap_factor``; :func:`time_reading`)."""

    radius: float
    endpoint_radius: float
    targets: dict[str, str]
    sigma: float | None = None
    floor: float | None = None
    zero_obstacles: bool = False  # the default obstacle rule (eval.zero_obstacles)
    cap_factor: float = 1.0  # a run's wall-clock cap, x planner.max_seconds (eval.cap_factor)


def time_reading(result: PlanResult, budget: float) -> dict:
    """The row fields of a run, made with a wall-clock cap above the time budget ``budget``
    (s), that the time readings see: the run as if the budget had stopped it. A run still
    going after ``budget`` s counts as stopped there (``success`` False, ``stop_reason``
    ``max_seconds``, ``time_to_stop`` = ``budget``), and a first solution or a convergence
    bound reached after it as not reached (NaN). Iterations, costs and ``run_stop_reason``
    stay the run's: the iteration readings see it stopped by the iteration budget only."""
    times = tuple(m.time for m in result.milestones)
    if result.time_to_stop <= budget:
        return {"success": result.success, "stop_reason": result.stop_reason,
                "time_to_first": result.time_to_first, "time_to_stop": result.time_to_stop,
                "convergence": times}  # fmt: skip
    first = result.time_to_first if result.time_to_first <= budget else math.nan
    return {"success": False, "stop_reason": "max_seconds", "time_to_first": first,
            "time_to_stop": budget, "convergence": tuple(t if t <= budget else math.nan
                                                        for t in times)}  # fmt: skip


def _row(job, inst, trial, seed, result, setup, ref, measured, budget) -> TrialRow:
    key = job.key
    return TrialRow(
        seq=job.seq + trial - job.first,
        instance=job.instance,
        map_set=inst.map_set,
        map=inst.map,
        cluster=inst.cluster,
        key=key.text,
        planner=key.planner,
        tau=math.nan if key.tau is None else float(key.tau),
        source=key.source or "",
        stop=job.stop,
        trial=trial,
        seed=seed,
        run_stop_reason=result.stop_reason,
        fallback_uniform=result.fallback_uniform,
        reference_length=ref,
        cost=result.cost,
        iterations=result.iterations,
        tree_size=result.tree_size,
        collision_checks=result.collision_checks,
        setup_time=setup,
        regime=job.regime,
        **time_reading(result, budget),
        **measured,
    )


def run_job(
    args: tuple[TrialJob, EvalInstance],
    seed: int,
    configs: dict[str, PlannerConfig],
    heat: TrialSettings,
) -> list[TrialRow]:
    """The rows of one job on its instance (``args``: the job and its instance);
    ``configs`` holds the planner settings of each regime cell (``''``: the protocol's)."""
    job, inst = args
    key, stop, config = job.key, job.stop, reuse.job_config(job, configs)
    budget = config.max_seconds  # the time readings' budget; the run's cap heat.cap_factor x
    if heat.cap_factor != 1.0:
        config = config.replace(max_seconds=budget * heat.cap_factor)
    warmup()
    free = free_rule(key, heat.zero_obstacles)
    allowed = sources.allowed_cells(inst.grid, free)
    heatmap, measured = None, {}
    if key.source is not None:
        heatmap = sources.source_heatmap(key.source, inst, heat.sigma, heat.floor, allowed)
        heatmap = sources.mask_variant(heatmap, key.mask, inst, heat.endpoint_radius)
        measured = _measure(key, heatmap, allowed, inst, heat)
    tick = time.perf_counter()
    sampler, config, fallback = build_sampler(key, heatmap, allowed, config, free)
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
            key.planner,
            sampler=sampler,
            stop="initial" if stop == "initial" else "optimal",
            reference_length=ref,
            seed=s,
            milestones=milestones,
            config=config,
        )
        r = dataclasses.replace(r, fallback_uniform=r.fallback_uniform or fallback)
        rows.append(_row(job, inst, trial, s, r, setup, ref, measured, budget))
    return rows


def _measure(key: ConfigKey, heatmap: np.ndarray, allowed: np.ndarray, inst: EvalInstance,
             heat: TrialSettings) -> dict:  # fmt: skip
    """What a configuration's heatmap is worth: its mass near its target (``heat_mass``), a
    uniform map's over the allowed cells (``uniform_mass``), and where the sampler's weights
    lie after the mask (:func:`vnrrt.evaluation.sources.mass_shares`)."""
    mask = sources.target_mask(inst, sources.source_target(key.source, heat.targets))
    weights = heatmap if key.tau is None else np.where(heatmap >= key.tau, heatmap, 0.0)
    return {
        "heat_mass": sources.mass_near(heatmap, mask, heat.radius),
        "uniform_mass": sources.mass_near(allowed.astype(np.float64), mask, heat.radius),
        **sources.mass_shares(weights, inst, heat.radius, heat.endpoint_radius),
    }


def _needed(job: TrialJob, inst: EvalInstance) -> tuple[TrialJob, EvalInstance]:
    """The job with an instance holding only the heatmap it samples (less to pickle)."""
    src = job.key.source
    if src is not None and not sources.is_oracle(src) and src not in inst.heatmaps:
        known = sorted(inst.heatmaps)
        raise HeatmapError(f"instance {inst.map} has no {src!r} heatmap (known: {known})")
    keep = {src: inst.heatmaps[src]} if src in inst.heatmaps else {}
    return job, dataclasses.replace(inst, heatmaps=keep)


def interleave(order: list[int], again: list[int]) -> list[tuple[int, bool]]:
    """``(item, is_repeat)`` in run order: ``order``, with each item of ``again`` run a
    second time, the repeats spread evenly over the run in reverse order (the first job's
    second run comes last), so that a drift of the machine's speed during the stage shows
    in the two timings as it shows between configurations."""
    slots: dict[int, list[int]] = {}
    for k, i in enumerate(reversed(again)):
        at = min(len(order), math.ceil((k + 1) * len(order) / len(again))) - 1
        slots.setdefault(at, []).append(i)
    out = []
    for p, i in enumerate(order):
        out += [(i, False), *((j, True) for j in slots.get(p, []))]
    return out


def _timed(rows: list[TrialRow], again: list[TrialRow]) -> list[TrialRow]:
    """``rows`` with the times of their second run (``again``, the same trials)."""
    return [
        dataclasses.replace(
            r, time_to_first_repeat=a.time_to_first, time_to_stop_repeat=a.time_to_stop
        )
        for r, a in zip(rows, again, strict=True)
    ]


def _run(fn, items: list, order: list[int], repeat: bool, workers: int) -> dict[int, list]:
    """``{item index: rows}`` of ``items[order]``; with ``repeat``, the jobs
    that :func:`~vnrrt.evaluation.protocol.timed_twice` picks run twice
    (:func:`interleave`) and their rows carry both timings."""
    again = [i for i in order if repeat and timed_twice(items[i][0])]
    schedule = interleave(order, again)
    done = parallel_map(fn, [items[i] for i, _ in schedule], workers, "trials")
    rows = {i: r for (i, second), r in zip(schedule, done, strict=True) if not second}
    for (i, second), r in zip(schedule, done, strict=True):
        if second:
            rows[i] = _timed(rows[i], r)
    return rows


def run_jobs(
    jobs: list[TrialJob],
    instances: dict[int, EvalInstance],
    seed: int,
    workers: int,
    config: PlannerConfig | dict[str, PlannerConfig],
    heat: TrialSettings,
    store: str | Path | None = None,
    repeat: bool = False,
) -> pd.DataFrame:
    """The rows of ``jobs`` (on ``instances[job.instance]``) as a trial table in ``seq``
    order. ``config``: the planner settings, or one per regime cell (label -> settings). A
    trial that exhausts a budget is a row with ``success=False``. With a ``store`` folder,
    a configuration whose inputs, settings and code are unchanged reuses its kept rows
    (:mod:`vnrrt.evaluation.reuse`) and the others' rows are kept there. With ``repeat``,
    the protocol's RRT* runs twice (the ``*_repeat`` columns: the machine's timing noise)."""
    configs = config if isinstance(config, dict) else {"": config}
    fn = functools.partial(run_job, seed=seed, configs=configs, heat=heat)
    items = [_needed(job, instances[job.instance]) for job in jobs]
    if store is None:
        rows = _run(fn, items, list(range(len(items))), repeat, workers)
        return frame([r for i in range(len(items)) for r in rows[i]])
    groups = reuse.group_digests(items, configs, heat, seed, reuse.code_digest(), repeat)
    tables, todo = [], []
    for key, idx in groups.values():
        table = reuse.load(store, key, [items[i][0] for i in idx])
        if table is None:
            todo.append((key, idx))
        else:
            tables.append(table)
    log.info(reuse.summary(len(tables), len(groups)))
    order = sorted(i for _, idx in todo for i in idx)  # the protocol's interleaved order
    rows = _run(fn, items, order, repeat, workers)
    for key, idx in todo:  # each configuration kept as soon as the pool is done
        tables.append(frame([r for i in idx for r in rows[i]]))
        reuse.keep(store, key, tables[-1])
    merged = pd.concat(tables, ignore_index=True) if tables else frame([])
    return conform(merged.sort_values("seq", kind="stable", ignore_index=True), "trial rows")


def run_trials(
    instances: list[EvalInstance],
    keys: list[ConfigKey],
    counts: dict[tuple[str, str], int],
    seed: int = 0,
    workers: int = 0,
    config: PlannerConfig | None = None,
    heat: TrialSettings | None = None,
) -> pd.DataFrame:
    """All trials of ``keys`` on ``instances`` (protocol order) as a table, for library
    callers; ``counts[(kind, stop)]`` trials per instance, kind ``'named'`` or ``'random'``;
    ``config``/``heat`` default to the library's :class:`PlannerConfig` and
    :data:`LIBRARY_SETTINGS` (the pipeline passes its config's, :func:`run_jobs`)."""
    jobs = trial_jobs([inst.kind for inst in instances], keys, counts)
    by_index = dict(enumerate(instances))
    settings = heat or LIBRARY_SETTINGS
    return run_jobs(jobs, by_index, seed, workers, config or PlannerConfig(), settings)


LIBRARY_SETTINGS = TrialSettings(3.0, 3.0, {}, sigma=1.0, floor=0.0)  # conf/oracle's, conf/eval's
