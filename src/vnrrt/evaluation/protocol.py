"""What the evaluation runs (paper, Experiments): planner configurations, stop rules, trial
counts per instance, seeds, and the split of the work into jobs and parts.

Nothing here plans or reads files; :mod:`vnrrt.evaluation.trials` runs the jobs,
:mod:`vnrrt.evaluation.table` stores their rows.

* **Instances**: protocol index ``i`` is named map ``i`` for ``i < 5`` (``map_1`` ..
  ``map_5``), else random test instance ``i - 5`` (:mod:`vnrrt.data.instances`).
* **Configurations** (:class:`~vnrrt.evaluation.keys.ConfigKey`): RRT*, NRRT*, VNRRT* and
  M-VNRRT* at every ``planner.taus`` value plus ``planner.tau``, each learned one sampling the
  heatmap of one source (a trained network or an oracle).
* **Stop rules** (:data:`STOPS`): ``initial`` (first solution), ``optimal`` (cost <= (1 +
  eps) x the A* length, the paper's) and ``optimal_any_angle`` (cost <= (1 + eps) x the
  exact continuous optimum; stricter, ours).
* **Seeds are paired**: trial ``t`` of instance ``i`` under stop rule ``s`` gets the same
  seed in every configuration (:func:`trial_seed`), so configurations are compared on the
  same instances with common random numbers, and the table does not depend on the number
  of workers, parts or the order of jobs.
"""

from __future__ import annotations

import zlib
from dataclasses import dataclass

import numpy as np

from vnrrt.config import ConfigError
from vnrrt.evaluation.config import Configurations, EvalConfig, mask_taus
from vnrrt.evaluation.keys import ConfigKey

STOPS = ("initial", "optimal", "optimal_any_angle")
# Trials of one (instance, configuration, stop) are cut into jobs of at most this many, so
# that a process pool and the parts of ``eval.parts`` share the work evenly.
TRIALS_PER_JOB = 25


def configurations(ev: Configurations, taus: list[float], tau: float) -> list[ConfigKey]:
    """The paper's configurations: every planner of ``ev.planners`` sampling its source of
    ``ev.sources``, M-VNRRT* once per threshold in ``taus`` (sorted, each once); with
    ``ev.informed`` each again with informed sampling (run on the random instances only);
    then, at the claims' threshold ``tau`` (``planner.tau``), M-VNRRT* with each mask variant
    of ``ev.mask_variants`` and, with ``ev.masked_controls``, on the path network's heatmap
    (the masked NRRT* control, ``m_vnrrt_star@tau[<nrrt_star's source>]``); with ``ev.gpu``
    (an :class:`EvalConfig`'s),
    NRRT*, VNRRT* and M-VNRRT* at ``tau`` on the GPU-trained paper networks' heatmaps
    (:data:`GPU_SOURCES`)."""
    keys = []
    for p in ev.planners:
        if p == "rrt_star":
            keys.append(ConfigKey(p))
        elif p == "m_vnrrt_star":
            keys += [ConfigKey(p, t, ev.sources[p]) for t in mask_taus(taus, None)]
        else:
            keys.append(ConfigKey(p, None, ev.sources[p]))
    if ev.informed:
        keys += [k.with_informed() for k in list(keys)]
    if "m_vnrrt_star" in ev.planners:
        masked = ConfigKey("m_vnrrt_star", float(tau), ev.sources["m_vnrrt_star"])
        keys += [masked.with_mask(m) for m in ev.mask_variants]
        if ev.masked_controls:
            keys.append(masked.with_source(ev.sources["nrrt_star"]))
    if isinstance(ev, EvalConfig) and ev.gpu:
        keys += [k.with_source(GPU_SOURCES[k.planner]) for k in _gpu_planned(ev, tau)]
    return keys


# planner -> the GPU-trained paper network it samples (vnrrt.data.returned.NETWORKS' names)
GPU_SOURCES = {"nrrt_star": "paper_nrrtnet", "vnrrt_star": "paper_vertexnet",
               "m_vnrrt_star": "paper_vertexnet"}  # fmt: skip


def _gpu_planned(ev: Configurations, tau: float) -> list[ConfigKey]:
    """The learned planners of ``ev.planners`` once each (M-VNRRT* at ``tau``)."""
    return [
        ConfigKey(p, float(tau) if p == "m_vnrrt_star" else None, ev.sources[p])
        for p in ev.planners
        if p in GPU_SOURCES
    ]


def trial_counts(ev: EvalConfig) -> dict[tuple[str, str], int]:
    """Trials per instance for each (instance kind, stop rule)."""
    strict = ev.named_optimal if ev.any_angle else 0
    return {
        ("named", "initial"): ev.named_initial,
        ("named", "optimal"): ev.named_optimal,
        ("named", "optimal_any_angle"): strict,
        ("random", "initial"): ev.random_initial,
        ("random", "optimal"): ev.random_optimal,
        ("random", "optimal_any_angle"): ev.random_optimal if ev.any_angle else 0,
    }


def trial_seed(seed: int, instance: int, stop: str, trial: int) -> int:
    """A 63-bit seed from (global seed, instance, stop rule, trial): the same for every
    planner configuration (paired trials, common random numbers)."""
    ss = np.random.SeedSequence([seed, instance, STOPS.index(stop), trial, 0x74726C])
    return int(ss.generate_state(1, np.uint64)[0] >> np.uint64(1))


@dataclass(frozen=True)
class TrialJob:
    """Trials ``first .. first + count - 1`` of one (instance, configuration, stop[, regime
    cell]); their rows are ``seq .. seq + count - 1`` of the whole table (canonical order:
    regime cell, instance, configuration, stop, trial)."""

    instance: int
    key: ConfigKey
    stop: str
    first: int
    count: int
    seq: int
    regime: str = ""


def timed_twice(job: TrialJob) -> bool:
    """Whether ``job`` runs twice when the stage measures the machine's timing noise
    (``eval.timing_noise``): the protocol's RRT* (every configuration is compared with it)
    outside the regime sweep."""
    return job.key == ConfigKey("rrt_star") and job.regime == ""


def trial_jobs(
    kinds: list[str],
    keys: list[ConfigKey],
    counts: dict[tuple[str, str], int],
    per_job: int = TRIALS_PER_JOB,
    regimes: tuple[str, ...] = ("",),
    instances: list[int] | None = None,
    seq: int = 0,
) -> list[TrialJob]:
    """Every job in canonical order; ``kinds[i]`` is ``'named'`` or ``'random'`` for
    instance ``i``, ``counts`` as :func:`trial_counts` returns; ``instances`` restricts the
    instances (default: all), ``regimes`` repeats everything per regime-sweep cell and ``seq``
    is the first row's number."""
    jobs = []
    chosen = range(len(kinds)) if instances is None else instances
    for regime in regimes:
        for i in chosen:
            for key in keys:
                for stop in STOPS:
                    n = counts.get((kinds[i], stop), 0)
                    if key.informed and kinds[i] == "named":
                        n = 0  # beyond the paper: the random instances only
                    for first in range(0, n, per_job):
                        count = min(per_job, n - first)
                        jobs.append(TrialJob(i, key, stop, first, count, seq, regime))
                        seq += count
    return jobs


def part_jobs(jobs: list[TrialJob], part: int, parts: int) -> list[TrialJob]:
    """The jobs of part ``part`` of ``parts``, in their order: those :func:`part_of` assigns
    to it (a hash, so each part gets a similar mix of instances, configurations and stop
    rules)."""
    if not 0 <= part < parts:
        raise ConfigError(f"part {part} is not in 0..{parts - 1}")
    return [job for job in jobs if part_of(job, parts) == part]


def part_of(job: TrialJob, parts: int) -> int:
    """The part of ``job`` among ``parts``: a hash of what the job runs (instance,
    configuration key, stop rule, first trial, regime cell), not of its place in the job
    list, so that a configuration's jobs keep their parts when an ablation adds or removes
    other configurations (and its kept rows are reused: :mod:`vnrrt.evaluation.reuse`)."""
    what = f"{job.instance}|{job.key.text}|{job.stop}|{job.first}|{job.regime}"
    return zlib.crc32(what.encode()) % parts
