"""What the evaluation runs (paper, Experiments): planner configurations, stop rules, trial
counts per instance, seeds, and the split of the work into jobs and parts.

Nothing here plans or reads files; :mod:`vnrrt.evaluation.trials` runs the jobs,
:mod:`vnrrt.evaluation.table` stores their rows.

* **Instances**: protocol index ``i`` is named map ``i`` for ``i < 5`` (``map_1`` ..
  ``map_5``), else random test instance ``i - 5`` (:mod:`vnrrt.evaluation.instances`).
* **Configurations** (:class:`PlannerSpec`): RRT*, NRRT*, VNRRT* and M-VNRRT* at every
  ``planner.taus`` value plus ``planner.tau``, each learned one sampling the heatmap of one
  source (a trained network or an oracle).
* **Stop rules** (:data:`STOPS`): ``initial`` (first solution), ``optimal`` (cost <= (1 +
  eps) x the A* length, the paper's) and ``optimal_any_angle`` (cost <= (1 + eps) x the
  exact continuous optimum; stricter, ours).
* **Seeds are paired**: trial ``t`` of instance ``i`` under stop rule ``s`` gets the same
  seed in every configuration (:func:`trial_seed`), so configurations are compared on the
  same instances with common random numbers, and the table does not depend on the number
  of workers, parts or the order of jobs.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from vnrrt.config import ConfigError
from vnrrt.evaluation.config import PLANNERS, EvalConfig

STOPS = ("initial", "optimal", "optimal_any_angle")
INFORMED = "+informed"  # key suffix of a configuration with informed sampling
KINDS = ("named", "random")
# Trials of one (instance, configuration, stop) are cut into jobs of at most this many, so
# that a process pool and the parts of ``eval.parts`` share the work evenly.
TRIALS_PER_JOB = 25


def planner_key(planner: str, tau: float | None = None) -> str:
    """Row key of a configuration: ``vnrrt_star`` or ``m_vnrrt_star@0.5`` (a heatmap source
    other than the protocol's is appended as ``[source]``: :func:`with_source`)."""
    return planner if tau is None or tau != tau else f"{planner}@{tau:g}"


@dataclass(frozen=True)
class PlannerSpec:
    """One evaluated configuration: a planner, its mask threshold and its heatmap source
    (``None`` for RRT*; else a name of :attr:`EvalInstance.heatmaps`)."""

    planner: str
    tau: float | None = None
    source: str | None = None
    key: str = ""  # row key; filled from the fields when empty
    informed: bool = False  # Informed RRT* sampling and skipping (ours, beyond the paper)

    def __post_init__(self) -> None:
        if self.planner not in PLANNERS:
            raise ConfigError(f"unknown planner {self.planner!r}; known: {PLANNERS}")
        if (self.planner == "rrt_star") != (self.source is None):
            raise ConfigError(f"{self.planner}: RRT* and only RRT* samples without a heatmap")
        if (self.planner == "m_vnrrt_star") != (self.tau is not None):
            raise ConfigError(f"{self.planner}: M-VNRRT* and only M-VNRRT* takes tau")
        if not self.key:
            suffix = INFORMED if self.informed else ""
            object.__setattr__(self, "key", planner_key(self.planner, self.tau) + suffix)


def planner_specs(ev: EvalConfig, taus: list[float]) -> list[PlannerSpec]:
    """The paper's configurations: every planner of ``ev.planners`` sampling its source of
    ``ev.sources``, M-VNRRT* once per threshold in ``taus`` (sorted, unique); with
    ``ev.informed`` each again with informed sampling (run on the random instances only)."""
    specs = []
    for p in ev.planners:
        if p == "rrt_star":
            specs.append(PlannerSpec(p))
        elif p == "m_vnrrt_star":
            specs += [PlannerSpec(p, t, ev.sources[p]) for t in sorted(set(taus))]
        else:
            specs.append(PlannerSpec(p, None, ev.sources[p]))
    if ev.informed:
        specs += [PlannerSpec(s.planner, s.tau, s.source, informed=True) for s in list(specs)]
    return specs


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


def parse_key(key: str, sources: dict[str, str] | None = None) -> PlannerSpec:
    """The configuration a row key names: ``rrt_star``, ``m_vnrrt_star@0.5``, or with a
    heatmap source ``vnrrt_star[oracle_vertex]`` (a network name or an oracle); without one,
    a learned planner samples its source in ``sources`` (``eval.sources``)."""
    informed = key.endswith(INFORMED)
    base, _, source = key.removesuffix(INFORMED).partition("[")
    planner, _, tau = base.partition("@")
    if source and not source.endswith("]"):
        raise ConfigError(f"bad configuration {key!r}: expected planner[@tau][[source]][+informed]")
    src = source[:-1] or (sources or {}).get(planner)
    try:
        return PlannerSpec(planner, float(tau) if tau else None, src, key, informed)
    except ValueError as err:
        raise ConfigError(f"bad configuration {key!r}: {err}") from None


def with_source(spec: PlannerSpec, source: str) -> PlannerSpec:
    """``spec`` sampling ``source`` instead, keyed ``<planner>[@tau][<source>]``."""
    key = f"{planner_key(spec.planner, spec.tau)}[{source}]"
    return PlannerSpec(spec.planner, spec.tau, source, key)


@dataclass(frozen=True)
class TrialJob:
    """Trials ``first .. first + count - 1`` of one (instance, configuration, stop[, regime
    cell]); their rows are ``seq .. seq + count - 1`` of the whole table (canonical order:
    regime cell, instance, configuration, stop, trial)."""

    instance: int
    spec: PlannerSpec
    stop: str
    first: int
    count: int
    seq: int
    regime: str = ""


def trial_jobs(
    kinds: list[str],
    specs: list[PlannerSpec],
    counts: dict[tuple[str, str], int],
    per_job: int = TRIALS_PER_JOB,
    regimes: tuple[str, ...] = ("",),
    instances: list[int] | None = None,
) -> list[TrialJob]:
    """Every job in canonical order; ``kinds[i]`` is ``'named'`` or ``'random'`` for
    instance ``i``, ``counts`` as :func:`trial_counts` returns; ``instances`` restricts the
    instances (default: all) and ``regimes`` repeats everything per regime-sweep cell."""
    jobs, seq = [], 0
    chosen = range(len(kinds)) if instances is None else instances
    for regime in regimes:
        for i in chosen:
            for spec in specs:
                for stop in STOPS:
                    n = counts.get((kinds[i], stop), 0)
                    if spec.informed and kinds[i] == "named":
                        n = 0  # beyond the paper: the random instances only
                    for first in range(0, n, per_job):
                        count = min(per_job, n - first)
                        jobs.append(TrialJob(i, spec, stop, first, count, seq, regime))
                        seq += count
    return jobs


def part_jobs(jobs: list[TrialJob], part: int, parts: int) -> list[TrialJob]:
    """The jobs of part ``part`` of ``parts``: every ``parts``-th job (round robin, so each
    part gets a similar mix of instances, configurations and stop rules)."""
    if not 0 <= part < parts:
        raise ConfigError(f"part {part} is not in 0..{parts - 1}")
    return jobs[part::parts]
