"""Statistics of planner trials: the paper's mean +- std, plus medians, bootstrap confidence
intervals, success rates and the paper's improvement percentages.

Improvement of a planner over a baseline is computed as the paper does:
``mean(baseline) / mean(planner) - 1`` (e.g. 19.38 / 3.71 - 1 = 422.37 %); positive means
the planner is faster. Standard deviations are sample standard deviations (ddof = 1).
Bootstrap intervals are percentile intervals over resampled trials, from a seeded
generator, so reports are reproducible.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np


@dataclass(frozen=True)
class Summary:
    """Summary of one metric over the successful trials of one planner on one map set."""

    n: int  # trials, failed ones included
    successes: int
    mean: float
    std: float
    median: float
    ci_low: float  # bootstrap CI of the mean
    ci_high: float

    @property
    def success_rate(self) -> float:
        return self.successes / self.n if self.n else float("nan")

    def as_dict(self) -> dict:
        return {**asdict(self), "success_rate": self.success_rate}


def bootstrap_means(values: np.ndarray, n_boot: int, rng: np.random.Generator) -> np.ndarray:
    """``(n_boot,)`` means of resamples (with replacement) of ``values`` ``(n,)``."""
    values = np.asarray(values, dtype=np.float64)
    idx = rng.integers(0, len(values), size=(n_boot, len(values)))
    return values[idx].mean(axis=1)


def summarize(
    values: np.ndarray, success: np.ndarray | None = None, *, n_boot: int = 2000,
    level: float = 0.95, seed: int = 0,
) -> Summary:  # fmt: skip
    """Summarize ``values`` ``(n,)`` over the trials where ``success`` ``(n,)`` is True.

    Failed trials count in ``n`` (and the success rate) but not in the statistics. With
    no successful trial every statistic is NaN.
    """
    values = np.asarray(values, dtype=np.float64)
    ok = np.ones(len(values), bool) if success is None else np.asarray(success, bool)
    v = values[ok]
    if len(v) == 0:
        nan = float("nan")
        return Summary(len(values), 0, nan, nan, nan, nan, nan)
    boots = bootstrap_means(v, n_boot, np.random.default_rng(seed))
    lo, hi = np.quantile(boots, [(1 - level) / 2, (1 + level) / 2])
    std = float(v.std(ddof=1)) if len(v) > 1 else 0.0
    return Summary(len(values), len(v), float(v.mean()), std, float(np.median(v)), lo, hi)


def improvement(baseline_mean: float, planner_mean: float) -> float:
    """The paper's improvement of a planner over a baseline: ``baseline / planner - 1``."""
    return baseline_mean / planner_mean - 1.0


def improvement_ci(
    baseline: np.ndarray, planner: np.ndarray, *, n_boot: int = 2000, level: float = 0.95,
    seed: int = 0,
) -> tuple[float, float, float]:  # fmt: skip
    """Improvement of ``planner`` over ``baseline`` (values of successful trials) with a
    bootstrap percentile CI: both samples are resampled independently.

    Returns ``(improvement, ci_low, ci_high)``.
    """
    rng = np.random.default_rng(seed)
    b = np.asarray(baseline, dtype=np.float64)
    p = np.asarray(planner, dtype=np.float64)
    ratios = bootstrap_means(b, n_boot, rng) / bootstrap_means(p, n_boot, rng) - 1.0
    lo, hi = np.quantile(ratios, [(1 - level) / 2, (1 + level) / 2])
    return improvement(b.mean(), p.mean()), float(lo), float(hi)


def verdict(quoted: float, ci_low: float, ci_high: float) -> str:
    """Compare a quoted improvement with our CI ``[ci_low, ci_high]``.

    * ``reproduced``: the CI excludes 0 on the side of the quoted sign and contains the
      quoted value; ``reproduced (smaller effect)`` / ``(larger effect)``: same direction,
      but the quoted value lies above / below the CI;
    * ``reversed``: the CI excludes 0 on the other side;
    * ``not reproduced``: the CI includes 0 (no clear effect either way).
    """
    if ci_low <= 0 <= ci_high:
        return "not reproduced"
    if (ci_low > 0) != (quoted > 0):
        return "reversed"
    if quoted > ci_high:
        return "reproduced (smaller effect)" if quoted > 0 else "reproduced (larger effect)"
    if quoted < ci_low:
        return "reproduced (larger effect)" if quoted > 0 else "reproduced (smaller effect)"
    return "reproduced"


def fmt_mean_std(mean: float, std: float, digits: int = 2) -> str:
    """``mean±std`` as the paper prints it (``nan`` if undefined)."""
    if not np.isfinite(mean):
        return "n/a"
    return f"{mean:.{digits}f}±{std:.{digits}f}"
