"""Statistics of the trial table: summaries with failures kept in, paired and clustered
comparisons of two configurations, and the verdict on a quoted claim.

Rules (stated in the report as well):

* **Failures are censored, not dropped.** A trial stopped by a budget enters the time and
  iteration statistics with the value at which it stopped, a lower bound of its true value.
  A mean over such values is a lower bound (shown as ``>=``); a median is exact while the
  failed trials are fewer than half and none of them lies below it. Path-length statistics
  are over successful trials only (a failed run may have no path); the success count is
  always shown beside them.
* **Comparisons are paired and clustered.** Every configuration runs on the same instances
  with the same trial seeds. The headline speed-up of a planner over a baseline is the
  geometric mean over instances of the per-instance ratio ``median(baseline) /
  median(planner)`` (iterations counted +1, so a root that sees the goal counts one step).
  Its confidence interval comes from a bootstrap over the three levels: base maps
  (clusters) are resampled with replacement, then instances within each drawn map, then
  trials within each instance (paired: trial t of both configurations together). A single
  trial of a single instance has no interval (NaN). The paper's ratio of means is computed
  beside it with the same resampling. Improvement = speed-up - 1 (the paper's
  ``baseline / planner - 1``).
* **Verdicts** (:func:`verdict`) compare a quoted improvement with our CI.

Every bootstrap draws from a seeded generator, so reports are reproducible.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np
import pandas as pd

from vnrrt.evaluation.table import solved

VERDICTS = (
    "reproduced",
    "same direction, smaller effect",
    "same direction, larger effect",
    "no clear effect",
    "reversed",
)


def improvement(baseline_mean: float, planner_mean: float) -> float:
    """The paper's improvement of a planner over a baseline: ``baseline / planner - 1``."""
    return baseline_mean / planner_mean - 1.0


def _cluster_weights(n_clusters: int, n_boot: int, rng: np.random.Generator) -> np.ndarray:
    """``(n_boot, C)`` how often each cluster is drawn when C clusters are resampled."""
    if n_clusters == 1:
        return np.ones((n_boot, 1))
    return rng.multinomial(n_clusters, np.full(n_clusters, 1.0 / n_clusters), size=n_boot)


def _within(groups: np.ndarray, n_boot: int, rng: np.random.Generator) -> np.ndarray:
    """``(n_boot, N)`` indices resampling each element's group with replacement: column j
    holds a random member of the group of element j (``groups`` (N,) int, sorted)."""
    starts = np.searchsorted(groups, groups, side="left")
    sizes = np.searchsorted(groups, groups, side="right") - starts
    return starts + (rng.random((n_boot, len(groups))) * sizes).astype(np.int64)


def _codes(labels) -> np.ndarray:
    """Dense int codes ``0..K-1`` of ``labels`` (N,) in order of first appearance."""
    _, first, inverse = np.unique(np.asarray(labels), return_index=True, return_inverse=True)
    return np.argsort(np.argsort(first))[inverse]


def bootstrap_means(
    values: np.ndarray, clusters: np.ndarray | None, n_boot: int, rng: np.random.Generator
) -> np.ndarray:
    """``(n_boot,)`` two-stage bootstrap means of ``values`` (N,): clusters (N,) resampled,
    then values within each cluster. ``clusters=None``: plain resampling of values."""
    values = np.asarray(values, np.float64)
    groups = np.zeros(len(values), np.int64) if clusters is None else _codes(clusters)
    order = np.argsort(groups, kind="stable")
    values, groups = values[order], groups[order]
    if clusters is None:  # one cluster holding everything = ordinary bootstrap
        weights = np.ones((n_boot, 1))
    else:
        weights = _cluster_weights(int(groups.max()) + 1, n_boot, rng)
    idx = _within(groups, n_boot, rng)
    w = weights[:, groups]  # (B, N)
    return (w * values[idx]).sum(axis=1) / w.sum(axis=1)


@dataclass(frozen=True)
class Summary:
    """One metric of one configuration on one map set (rules in the module doc)."""

    n: int  # trials
    successes: int
    budget_hits: int  # trials stopped by a budget (failures)
    fallbacks: int  # trials whose heatmap sampler fell back to uniform
    mean: float
    std: float
    median: float
    ci_low: float  # bootstrap CI of the mean (clusters, then trials)
    ci_high: float
    censored: bool  # failures entered at their stop value: the mean is a lower bound
    median_exact: bool  # the median is not affected by censoring

    @property
    def success_rate(self) -> float:
        return self.successes / self.n if self.n else float("nan")

    def as_dict(self) -> dict:
        return {**asdict(self), "success_rate": self.success_rate}


def summarize(
    values,
    success,
    clusters=None,
    fallback=None,
    *,
    censor: bool = True,
    n_boot: int = 2000,
    level: float = 0.95,
    seed: int = 0,
) -> Summary:
    """Summary of ``values`` (N,) with ``success`` (N,) bool, ``clusters`` (N,) base-map ids
    and ``fallback`` (N,) bool. ``censor=True`` keeps failed trials at their recorded value
    (times, iterations); ``censor=False`` summarizes successful trials only (path length)."""
    values = np.asarray(values, np.float64)
    ok = np.asarray(success, bool)
    n, successes = len(values), int(ok.sum())
    fallbacks = 0 if fallback is None else int(np.asarray(fallback, bool).sum())
    keep = np.ones(n, bool) if censor else ok
    v = values[keep]
    if len(v) == 0:
        nan = float("nan")
        return Summary(
            n, successes, n - successes, fallbacks, nan, nan, nan, nan, nan, False, False
        )
    cl = None if clusters is None else np.asarray(clusters)[keep]
    boots = bootstrap_means(v, cl, n_boot, np.random.default_rng(seed))
    lo, hi = np.quantile(boots, [(1 - level) / 2, (1 + level) / 2])
    median = float(np.median(v))
    failed = v[~ok[keep]]
    exact = len(failed) < len(v) / 2 and bool(np.all(failed >= median))
    std = float(v.std(ddof=1)) if len(v) > 1 else 0.0
    return Summary(
        n,
        successes,
        n - successes,
        fallbacks,
        float(v.mean()),
        std,
        median,
        float(lo),
        float(hi),
        bool(len(failed)),
        exact,
    )


@dataclass(frozen=True)
class Comparison:
    """A planner against a baseline on the same instances (rules in the module doc).

    ``speedup`` is the geometric mean over instances of ``median(baseline) /
    median(planner)``; ``ratio_of_means`` the paper's ``mean(baseline) / mean(planner)``;
    each with its bootstrap CI. Improvements are these minus 1.
    """

    speedup: float
    ci_low: float
    ci_high: float
    ratio_of_means: float
    rom_ci_low: float
    rom_ci_high: float
    instances: int
    clusters: int
    trials: int
    failed_baseline: int
    failed_planner: int

    def as_dict(self) -> dict:
        return asdict(self)


def _paired(base: pd.DataFrame, plan: pd.DataFrame, metric: str) -> dict[str, np.ndarray]:
    """Both configurations' rows joined on (instance, trial), sorted by (instance, trial):
    ``(N,)`` arrays instance, trial, then cluster, ``metric`` and success suffixed ``_b``
    (base) and ``_p`` (plan). Each configuration is sorted on its own, then checked to hold
    the same unique pairs (what an inner merge with a row-count check tests, at a fraction of
    its cost: a comparison is made hundreds of times per report)."""
    keys = ["instance", "trial"]
    cols = [*keys, "cluster", metric, "success"]  # success as the metric's reading counts it
    b, p = ({c: v.to_numpy() for c, v in t[cols[:-1]].assign(success=solved(t, metric))
             .sort_values(keys, kind="stable").items()} for t in (base, plan))  # fmt: skip
    same = len(b["trial"]) == len(p["trial"]) and all(np.array_equal(b[k], p[k]) for k in keys)
    if not same or pd.MultiIndex.from_arrays([b[k] for k in keys]).has_duplicates:
        raise ValueError(
            f"{metric}: the two configurations were not run on the same "
            f"(instance, trial) pairs; a paired comparison needs both"
        )
    rest = {f"{c}{s}": t[c] for c in cols[2:] for s, t in (("_b", b), ("_p", p))}
    return {"instance": b["instance"], "trial": b["trial"], **rest}


def compare(
    base: pd.DataFrame,
    plan: pd.DataFrame,
    metric: str,
    *,
    n_boot: int = 2000,
    level: float = 0.95,
    seed: int = 0,
) -> Comparison:
    """Paired, clustered comparison of ``plan`` against ``base`` (trial tables of one map
    set and stop rule: columns instance, trial, cluster, success and ``metric``)."""
    j = _paired(base, plan, metric)
    if not len(j["trial"]):
        raise ValueError(f"{metric}: no trials to compare")
    shift = 1.0 if metric == "iterations" else 0.0
    b = j[f"{metric}_b"].astype(np.float64) + shift
    p = j[f"{metric}_p"].astype(np.float64) + shift
    inst = _codes(j["instance"])
    first = np.r_[0, np.flatnonzero(np.diff(inst)) + 1]  # each instance's first row (sorted)
    clusters = _codes(j["cluster_b"][first])
    rng = np.random.default_rng(seed)
    idx = np.vstack([np.arange(len(b)), _within(inst, n_boot, rng)])  # row 0: the data
    w_inst = np.vstack([np.ones(len(clusters)), _instance_weights(clusters, n_boot, rng)])
    log_ratio = np.log(_group_medians(b[idx], inst)) - np.log(_group_medians(p[idx], inst))
    gm = np.exp((w_inst * log_ratio).sum(1) / w_inst.sum(1))
    sums_b, sums_p = _group_sums(b[idx], inst), _group_sums(p[idx], inst)
    rom = (w_inst * sums_b).sum(1) / (w_inst * sums_p).sum(1)
    q = [(1 - level) / 2, (1 + level) / 2]
    lo, hi = np.quantile(gm[1:], q)
    rlo, rhi = np.quantile(rom[1:], q)
    if len(clusters) == 1 and len(b) == 1:  # one trial of one instance: no interval
        lo = hi = rlo = rhi = float("nan")
    return Comparison(
        float(gm[0]),
        float(lo),
        float(hi),
        float(rom[0]),
        float(rlo),
        float(rhi),
        int(inst.max()) + 1,
        int(clusters.max()) + 1,
        len(b),
        int((~j["success_b"].astype(bool)).sum()),
        int((~j["success_p"].astype(bool)).sum()),
    )


def _instance_weights(clusters: np.ndarray, n_boot: int, rng: np.random.Generator) -> np.ndarray:
    """``(n_boot, I)`` how often each instance enters a resample: clusters (base maps) are
    drawn with replacement, then instances with replacement within each drawn cluster.
    ``clusters`` (I,) are the instances' cluster codes."""
    n = len(clusters)
    per_cluster = _cluster_weights(int(clusters.max()) + 1, n_boot, rng)[:, clusters]
    order = np.argsort(clusters, kind="stable")
    chosen = order[_within(clusters[order], n_boot, rng)]  # (B, I) instance ids
    flat = (chosen + n * np.arange(n_boot)[:, None]).ravel()
    within = np.bincount(flat, minlength=n_boot * n).reshape(n_boot, n)
    return per_cluster * within


def _group_medians(x: np.ndarray, groups: np.ndarray) -> np.ndarray:
    """``(B, G)`` medians of the columns of ``x`` (B, N) per group (``groups`` (N,) sorted)."""
    bounds = np.flatnonzero(np.diff(groups)) + 1
    return np.stack([np.median(s, axis=1) for s in np.split(x, bounds, axis=1)], axis=1)


def _group_sums(x: np.ndarray, groups: np.ndarray) -> np.ndarray:
    """``(B, G)`` sums of the columns of ``x`` (B, N) per group (``groups`` (N,) sorted)."""
    bounds = np.r_[0, np.flatnonzero(np.diff(groups)) + 1]
    return np.add.reduceat(x, bounds, axis=1)


def verdict(quoted: float, ci_low: float, ci_high: float) -> str:
    """Compare a quoted improvement (e.g. 0.7682 for "76.82 % faster") with our CI of it.

    * ``reproduced``: the CI excludes 0 on the quoted side and contains the quoted value;
    * ``same direction, smaller effect`` / ``larger effect``: the CI excludes 0 on the quoted
      side, but the quoted value lies outside it;
    * ``no clear effect``: the CI contains 0 (no effect either way);
    * ``reversed``: the CI excludes 0 on the other side.
    """
    if not (np.isfinite(ci_low) and np.isfinite(ci_high)):
        return "no clear effect"
    if ci_low <= 0 <= ci_high:
        return "no clear effect"
    if (ci_low > 0) != (quoted > 0):
        return "reversed"
    if ci_low <= quoted <= ci_high:
        return "reproduced"
    smaller = abs(quoted) > max(abs(ci_low), abs(ci_high))
    return f"same direction, {'smaller' if smaller else 'larger'} effect"


def bonferroni_level(level: float, tests: int) -> float:
    """Per-test confidence level that keeps the family-wise level over ``tests`` tests."""
    return 1.0 - (1.0 - level) / max(tests, 1)
