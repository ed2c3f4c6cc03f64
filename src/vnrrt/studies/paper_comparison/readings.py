"""A claim read four ways, judged against the paper's own data by the interval of the
difference.

* **Readings.** The paper's estimand is the ratio of means (``mean(baseline) /
  mean(planner)``); ours is the geometric mean over instances of ``median(baseline) /
  median(planner)``. Each is read on planning time and on iterations (:data:`READINGS`);
  the claim's verdict is the primary reading's (:data:`PRIMARY`), and its *robustness* says
  whether the other readings give the same category, or which one moves it
  (:func:`robustness`).
* **The difference with the paper.** Ours and the paper's ratio are compared by the
  interval of their ratio (a difference on the log scale): ``log ours - log paper`` with
  ``se = sqrt(se_ours^2 + se_paper^2)``, each ``se`` read off its own interval as
  ``(log high - log low) / (2 z)`` (the two are independent samples). Our reading is
  *compatible with the paper's data* when that interval contains 1, and *contradicts* it when
  it does not (:func:`compatibility`); a verdict says "smaller" or "larger effect" only where
  the difference interval excludes 1 (:func:`reading_verdict`), and "size within the paper's
  noise" where the quoted value is outside our interval but the difference is not
  significant.
"""

from __future__ import annotations

import math

from scipy.stats import norm

from vnrrt.evaluation.stats import verdict

COMPATIBLE, CONTRADICTS = "compatible with the paper's data", "contradicts the paper's data"
WITHIN_NOISE = "same direction, size within the paper's noise"
READINGS = {  # label -> (metric, estimate, CI low, CI high) of a Comparison dict
    "time, gm of ratios of medians": ("time_to_stop", "speedup", "ci_low", "ci_high"),
    "time, ratio of means": ("time_to_stop", "ratio_of_means", "rom_ci_low", "rom_ci_high"),
    "iterations, gm of ratios of medians": ("iterations", "speedup", "ci_low", "ci_high"),
    "iterations, ratio of means": ("iterations", "ratio_of_means", "rom_ci_low", "rom_ci_high"),
}
PRIMARY = "time, gm of ratios of medians"
ITERATIONS = "iterations, gm of ratios of medians"  # the second reading beside the verdict
PAPERS = "time, ratio of means"  # the paper's estimand on the paper's metric


def _z(level: float) -> float:
    return float(norm.ppf(0.5 + level / 2))


def log_se(low: float, high: float, level: float) -> float:
    """The standard error of a log ratio read off its ``level`` interval of the ratio
    ``[low, high]`` (both > 0): ``(log high - log low) / (2 z)``; NaN if not finite."""
    if not (math.isfinite(low) and math.isfinite(high)) or min(low, high) <= 0:
        return math.nan
    return (math.log(high) - math.log(low)) / (2 * _z(level))


def difference(ours: tuple[float, float, float], paper: dict, level: float) -> dict:
    """The ratio ``ours / paper`` of two speed-ups with its ``level`` interval (module doc).
    ``ours``: (ratio, CI low, CI high); ``paper``: the paper's interval
    (:class:`~.paper_noise.PaperInterval` dict: ``improvement``, ``low``, ``high``, ratio - 1)."""
    est, lo, hi = ours
    se = math.hypot(log_se(lo, hi, level), log_se(1 + paper["low"], 1 + paper["high"], level))
    if not (math.isfinite(se) and est > 0):
        return {"ratio": math.nan, "low": math.nan, "high": math.nan}
    d, z = math.log(est) - math.log(1 + paper["improvement"]), _z(level)
    return {"ratio": math.exp(d), "low": math.exp(d - z * se), "high": math.exp(d + z * se)}


def compatibility(diff: dict) -> str:
    """:data:`COMPATIBLE` when the difference interval contains 1 (or is undefined), else
    :data:`CONTRADICTS`."""
    lo, hi = diff["low"], diff["high"]
    if not (math.isfinite(lo) and math.isfinite(hi)):
        return COMPATIBLE
    return COMPATIBLE if lo <= 1 <= hi else CONTRADICTS


def reading_verdict(quoted: float, low: float, high: float, diff: dict) -> str:
    """The verdict of one reading: :func:`vnrrt.evaluation.stats.verdict` of the quoted
    improvement against our CI of the improvement ``[low, high]``, with "smaller/larger
    effect" kept only where the difference interval ``diff`` excludes 1 (else
    :data:`WITHIN_NOISE`); smaller means closer to no effect than the paper's."""
    v = verdict(quoted, low, high)
    if not v.startswith("same direction"):
        return v
    if compatibility(diff) == COMPATIBLE:
        return WITHIN_NOISE
    ours_below = diff["high"] < 1  # our ratio is significantly below the paper's
    smaller = ours_below == (quoted > 0)
    return f"same direction, {'smaller' if smaller else 'larger'} effect"


def read_claim(readings: dict, quoted: float, paper: dict, level: float) -> dict:
    """``{label: {estimate, ci_low, ci_high, difference, verdict}}`` for every reading of
    :data:`READINGS` whose metric ``readings`` holds (``{metric: Comparison dict}``);
    estimates are ratios (speed-ups), ``paper`` the paper's interval dict."""
    out = {}
    for name, (metric, est, lo, hi) in READINGS.items():
        c = readings.get(metric)
        if c is None:
            continue
        diff = difference((c[est], c[lo], c[hi]), paper, level)
        v = reading_verdict(quoted, c[lo] - 1, c[hi] - 1, diff)
        out[name] = {"estimate": c[est], "ci_low": c[lo], "ci_high": c[hi],
                     "difference": diff, "verdict": v}  # fmt: skip
    return out


def category(v: str) -> str:
    """A verdict's category: ``reproduced``, ``same direction``, ``no clear effect``,
    ``reversed``."""
    return "same direction" if v.startswith("same direction") else v


def robustness(read: dict) -> str:
    """``same under all readings`` when every reading of ``read`` (:func:`read_claim`) has
    the primary reading's category, else the readings that move it, with their verdicts."""
    if PRIMARY not in read:
        return "no data"
    base = category(read[PRIMARY]["verdict"])
    moved = [f"{n}: {r['verdict']}" for n, r in read.items() if category(r["verdict"]) != base]
    return "same under all readings" if not moved else "moved by " + "; ".join(moved)
