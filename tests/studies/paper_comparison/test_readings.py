"""The four readings of a claim on synthetic trials where the paper's estimand (ratio of
means) and ours (geometric mean of per-instance ratios of medians) disagree, checked against
numpy; the interval of the difference and the paper's pairing sensitivity against parametric
simulations; the verdict refinement and the honest headline counts."""

import math

import numpy as np
import pandas as pd
import pytest

from vnrrt.evaluation.stats import compare
from vnrrt.studies.paper_comparison.headline import headline
from vnrrt.studies.paper_comparison.paper_noise import ratio_interval
from vnrrt.studies.paper_comparison.readings import (
    COMPATIBLE,
    CONTRADICTS,
    WITHIN_NOISE,
    compatibility,
    difference,
    read_claim,
    reading_verdict,
    robustness,
)

LEVEL = 0.99


def heavy_tailed(seed: int = 0) -> tuple[pd.DataFrame, pd.DataFrame]:
    """200 instances (one base map each), 3 trials: on 20 the planner is 20x faster
    (baseline 200 s, planner 10 s), on 180 it is 2x slower (1 s against 2 s); times jitter
    by 1%. Ratio of means ~7.5 (a few long baseline runs dominate), gm of ratios ~0.73."""
    rng = np.random.default_rng(seed)
    rows_b, rows_p = [], []
    for i in range(200):
        b, p = (200.0, 10.0) if i % 10 == 0 else (1.0, 2.0)
        for t in range(3):
            common = {"instance": i, "trial": t, "cluster": i, "success": True}
            jb, jp = 1 + 0.01 * rng.standard_normal(2)
            rows_b.append({**common, "time_to_stop": b * jb, "iterations": int(1000 * b)})
            rows_p.append({**common, "time_to_stop": p * jp, "iterations": int(1000 * p)})
    return pd.DataFrame(rows_b), pd.DataFrame(rows_p)


def test_the_estimands_disagree_as_numpy_computes_them():
    base, plan = heavy_tailed()
    c = compare(base, plan, "time_to_stop", n_boot=2000, level=LEVEL)
    mb = base.groupby("instance")["time_to_stop"].median()
    mp = plan.groupby("instance")["time_to_stop"].median()
    assert c.speedup == pytest.approx(np.exp(np.mean(np.log(mb / mp))), rel=1e-12)
    assert c.ratio_of_means == pytest.approx(
        base["time_to_stop"].sum() / plan["time_to_stop"].sum(), rel=1e-12
    )
    assert c.ci_high < 1 < c.rom_ci_low  # significant, and in opposite directions


def test_one_verdict_per_reading_and_the_robustness_names_what_moves_it():
    base, plan = heavy_tailed()
    readings = {m: compare(base, plan, m, n_boot=2000, level=LEVEL).as_dict()
                for m in ("time_to_stop", "iterations")}  # fmt: skip
    paper = ratio_interval((30.0, 60.0, 100), (10.0, 20.0, 100), LEVEL).as_dict()  # +200%
    read = read_claim(readings, paper["improvement"], paper, LEVEL)
    verdicts = {n: r["verdict"] for n, r in read.items()}
    assert verdicts["time, gm of ratios of medians"] == "reversed"
    assert verdicts["iterations, gm of ratios of medians"] == "reversed"
    assert verdicts["time, ratio of means"].startswith("same direction")  # ~+650% vs +200%
    assert verdicts["time, ratio of means"] == verdicts["iterations, ratio of means"]
    text = robustness(read)
    assert text.startswith("moved by") and "time, ratio of means" in text
    assert "gm of ratios" not in text  # the primary's category is not "moved"
    same = {n: {**r, "verdict": "reversed"} for n, r in read.items()}
    assert robustness(same) == "same under all readings"


def test_the_difference_interval_matches_a_parametric_simulation():
    ours = (0.5, 0.4, 0.625)  # ratio 0.5, a symmetric log interval at LEVEL
    paper = ratio_interval((20.0, 40.0, 100), (10.0, 30.0, 100), LEVEL).as_dict()
    d = difference(ours, paper, LEVEL)
    rng = np.random.default_rng(1)
    z = 2.5758293035489  # the normal quantile at 99.5%
    se_o = (math.log(0.625) - math.log(0.4)) / (2 * z)
    se_p = (math.log(1 + paper["high"]) - math.log(1 + paper["low"])) / (2 * z)
    draws = (rng.normal(math.log(0.5), se_o, 400_000)
             - rng.normal(math.log(1 + paper["improvement"]), se_p, 400_000))  # fmt: skip
    lo, hi = np.exp(np.quantile(draws, [0.005, 0.995]))
    assert d["ratio"] == pytest.approx(0.5 / 2.0)
    assert (d["low"], d["high"]) == pytest.approx((lo, hi), rel=0.01)


def test_the_pairing_sensitivity_matches_a_correlated_simulation():
    base, plan, rho = (20.0, 10.0, 100), (10.0, 4.0, 100), 0.9  # 5% and 4% standard errors
    paired = ratio_interval(base, plan, 0.95, rho)
    unpaired = ratio_interval(base, plan, 0.95)
    assert unpaired.low < paired.low < paired.high < unpaired.high  # pairing narrows it
    rng = np.random.default_rng(2)
    sb, sp = base[1] / 10, plan[1] / 10  # the means' standard errors (n = 100)
    cov = [[sb**2, rho * sb * sp], [rho * sb * sp, sp**2]]
    mb, mp = rng.multivariate_normal([base[0], plan[0]], cov, 400_000).T
    keep = (mb > 0) & (mp > 0)
    r = np.log(mb[keep] / mp[keep])  # the delta method is on the log scale
    lo, hi = np.quantile(r, [0.025, 0.975])
    assert math.log(1 + paired.low) == pytest.approx(lo, abs=0.005)
    assert math.log(1 + paired.high) == pytest.approx(hi, abs=0.005)


@pytest.mark.parametrize(
    ("quoted", "ours", "diff", "want"),
    [
        (0.77, (0.5, 1.0), (0.5, 1.5), "reproduced"),
        (0.77, (0.1, 0.3), (0.3, 1.2), WITHIN_NOISE),  # the paper's own noise covers it
        (0.77, (0.1, 0.3), (0.3, 0.8), "same direction, smaller effect"),
        (0.77, (1.2, 2.0), (1.1, 1.9), "same direction, larger effect"),
        (-0.4, (-0.2, -0.1), (1.2, 1.6), "same direction, smaller effect"),  # a slow-down
        (-0.1, (-0.6, -0.4), (0.5, 0.8), "same direction, larger effect"),
        (0.77, (-0.1, 0.4), (0.3, 0.9), "no clear effect"),
        (0.77, (-0.6, -0.2), (0.1, 0.5), "reversed"),
    ],
)
def test_smaller_or_larger_only_where_the_difference_says_so(quoted, ours, diff, want):
    d = {"ratio": math.sqrt(diff[0] * diff[1]), "low": diff[0], "high": diff[1]}
    assert reading_verdict(quoted, *ours, d) == want


def test_compatibility_by_the_difference_not_by_overlap():
    # ours [+10%, +30%] and the paper's [+20%, +80%] overlap, yet their ratio can be judged
    assert compatibility({"ratio": 0.7, "low": 0.5, "high": 0.9}) == CONTRADICTS
    assert compatibility({"ratio": 0.9, "low": 0.6, "high": 1.2}) == COMPATIBLE
    assert compatibility({"ratio": math.nan, "low": math.nan, "high": math.nan}) == COMPATIBLE


def _row(verdict: str, testable: bool, data: str) -> dict:
    return {"time_to_stop": {"speedup": 1.0}, "verdict": verdict, "paper_data": data,
            "testability": {"testable": testable, "why": ""}}  # fmt: skip


def test_untestable_claims_get_no_verdict_in_the_counts():
    rows = [_row("reversed", False, CONTRADICTS), _row("reversed", False, CONTRADICTS),
            _row("reproduced", True, COMPATIBLE), _row("reversed", True, CONTRADICTS),
            {"time_to_stop": None, "verdict": "no data", "paper_data": None,
             "testability": {"testable": True, "why": ""}}]  # fmt: skip
    out = headline({"cells": {}, "claims": {"rows": rows}}, {}, 0.5)
    assert out["testable"] == 2 and out["untestable"] == 2
    assert out["contradicting"] == 1
    counts = {k: out[k] for k in ("reproduced", "same_dir", "no_effect", "reversed")}
    assert counts == {"reproduced": 1, "same_dir": 0, "no_effect": 0, "reversed": 1}
