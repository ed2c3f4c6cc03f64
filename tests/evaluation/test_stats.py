"""Statistics against hand computations and known truths: censored summaries, the paired
clustered speed-up and its interval, verdicts, and the paper's own arithmetic."""

import math

import numpy as np
import pandas as pd
import pytest

from vnrrt.evaluation.stats import (
    bootstrap_means,
    compare,
    improvement,
    summarize,
    verdict,
)
from vnrrt.studies.paper_tables import load_paper_tables


def test_summary_matches_hand_computation():
    s = summarize([1.0, 2.0, 3.0, 4.0], [True] * 4)
    assert (s.n, s.successes, s.budget_hits, s.success_rate) == (4, 4, 0, 1.0)
    assert s.mean == 2.5 and s.median == 2.5 and not s.censored and s.median_exact
    assert s.std == pytest.approx(math.sqrt(((1.5**2) * 2 + (0.5**2) * 2) / 3))
    assert 1.0 <= s.ci_low < 2.5 < s.ci_high <= 4.0


def test_failures_are_censored_at_their_stop_value_not_dropped():
    """Rule: a failed trial enters at the value where its budget stopped it; the mean is then
    a lower bound; the median stays exact while failures are fewer than half (and above it)."""
    ok = [True, True, True, True, False]
    s = summarize([1.0, 2.0, 3.0, 4.0, 100.0], ok)
    assert s.mean == pytest.approx(22.0) and s.median == 3.0  # 100 counted, not dropped
    assert s.censored and s.median_exact and s.budget_hits == 1
    dropped = summarize([1.0, 2.0, 3.0, 4.0, 100.0], ok, censor=False)  # path lengths
    assert dropped.mean == 2.5 and dropped.successes == 4 and dropped.n == 5
    half = summarize([1.0, 2.0, 50.0, 60.0], [True, True, False, False])
    assert half.censored and not half.median_exact  # a lower bound only
    low = summarize([5.0, 6.0, 7.0, 1.0, 8.0], [True, True, True, False, True])
    assert not low.median_exact  # a failure below the median: the median is not exact
    none = summarize([5.0], [False], censor=False)
    assert none.successes == 0 and math.isnan(none.mean)


def test_fallbacks_are_counted():
    s = summarize([1.0, 2.0, 3.0], [True] * 3, fallback=[True, False, True])
    assert s.fallbacks == 2


def test_cluster_bootstrap_of_a_mean_resamples_clusters():
    """Two clusters with very different means: resampling clusters gives means near both
    cluster means; plain resampling of 200 values almost never does."""
    values = np.r_[np.zeros(100), np.ones(100)]
    clusters = np.r_[np.zeros(100), np.ones(100)]
    rng = np.random.default_rng(0)
    clustered = bootstrap_means(values, clusters, 2000, rng)
    plain = bootstrap_means(values, None, 2000, rng)
    assert np.mean(np.abs(clustered - 0.5) > 0.4) > 0.3  # all-0 or all-1 resamples
    assert np.std(clustered) > 5 * np.std(plain)


def paired_table(
    ratio: float,
    maps: int,
    per_map: int,
    trials: int,
    map_sd: float,
    seed: int = 0,
    base_sd: float = 1.0,
) -> tuple[pd.DataFrame, pd.DataFrame]:
    """Baseline and planner tables on the same instances: per-instance base times (sd
    ``base_sd`` in log); the planner is ``ratio`` times faster times a per-map factor (sd
    ``map_sd`` in log) shared by the instances of a map, and trial noise."""
    rng = np.random.default_rng(seed)
    rows_b, rows_p = [], []
    for m in range(maps):
        effect = math.exp(rng.normal(0, map_sd))
        for k in range(per_map):
            inst = m * per_map + k
            base = math.exp(rng.normal(0, base_sd))
            for t in range(trials):
                noise = math.exp(rng.normal(0, 0.2))
                row = {"instance": inst, "trial": t, "cluster": m, "success": True}
                rows_b.append({**row, "time_to_stop": base * noise, "iterations": 100 * base})
                p = base / ratio * effect * math.exp(rng.normal(0, 0.2))
                rows_p.append({**row, "time_to_stop": p, "iterations": 100 * base / ratio})
    return pd.DataFrame(rows_b), pd.DataFrame(rows_p)


def test_paired_speedup_recovers_a_known_ratio():
    base, plan = paired_table(ratio=2.0, maps=60, per_map=3, trials=3, map_sd=0.1)
    c = compare(base, plan, "time_to_stop", n_boot=1000)
    assert c.ci_low < 2.0 < c.ci_high and 1.8 < c.speedup < 2.2
    assert c.instances == 180 and c.clusters == 60 and c.trials == 540
    it = compare(base, plan, "iterations", n_boot=500)  # noiseless, iterations counted + 1
    first = base.groupby("instance")["iterations"].first().to_numpy()
    exact = math.exp(np.mean(np.log((first + 1) / (first / 2 + 1))))
    assert it.speedup == pytest.approx(exact, rel=1e-12) and it.ci_high - it.ci_low < 0.05


def unpaired_ratio_of_means_ci(base: np.ndarray, plan: np.ndarray, n_boot: int = 1000):
    """The old interval: both samples resampled independently, ratio of means."""
    rng = np.random.default_rng(0)
    b = bootstrap_means(base, None, n_boot, rng)
    p = bootstrap_means(plan, None, n_boot, rng)
    return np.quantile(b / p, [0.025, 0.975])


def test_clustered_interval_is_wider_when_instances_of_a_map_are_correlated():
    """With a shared per-map effect on the speed-up, 12 maps carry the information, not 120
    instances: resampling maps gives a wider (honest) interval than resampling instances as
    if they were independent, and than the old unpaired interval (both configurations
    resampled independently, ratio of means)."""
    base, plan = paired_table(2.0, maps=12, per_map=10, trials=1, map_sd=0.5, base_sd=0.1)
    clustered = compare(base, plan, "time_to_stop", n_boot=2000)
    flat = compare(
        base.assign(cluster=base["instance"]),
        plan.assign(cluster=plan["instance"]),
        "time_to_stop",
        n_boot=2000,
    )
    lo, hi = unpaired_ratio_of_means_ci(
        base["time_to_stop"].to_numpy(), plan["time_to_stop"].to_numpy()
    )
    width = math.log(clustered.ci_high / clustered.ci_low)
    assert width > 1.5 * math.log(flat.ci_high / flat.ci_low)
    assert width > 1.5 * math.log(hi / lo)
    assert clustered.ci_low < 2.0 < clustered.ci_high and clustered.clusters == 12


def test_pairing_narrows_the_interval_when_instances_differ_a_lot():
    """Without map effects but with instances of very different difficulty, comparing each
    instance with itself removes that spread: the paired interval is narrower than the old
    unpaired one."""
    base, plan = paired_table(2.0, maps=40, per_map=1, trials=1, map_sd=0.0, base_sd=1.0)
    paired = compare(base, plan, "time_to_stop", n_boot=2000)
    lo, hi = unpaired_ratio_of_means_ci(
        base["time_to_stop"].to_numpy(), plan["time_to_stop"].to_numpy()
    )
    assert math.log(paired.ci_high / paired.ci_low) < 0.5 * math.log(hi / lo)


def test_pairing_needs_the_same_instances_and_trials():
    base, plan = paired_table(ratio=2.0, maps=3, per_map=2, trials=2, map_sd=0.1)
    with pytest.raises(ValueError, match="same \\(instance, trial\\) pairs"):
        compare(base, plan.iloc[:-1], "time_to_stop")


def test_failures_change_the_comparison_as_the_rule_says():
    """A planner failing on half its trials at a budget of 10 s: its censored times enter at
    10 s, so its speed-up drops below the speed-up of its successful trials alone."""
    base, plan = paired_table(ratio=4.0, maps=20, per_map=1, trials=4, map_sd=0.05)
    failed = plan.copy()
    hit = failed["trial"] < 2
    failed.loc[hit, "time_to_stop"] = 10.0
    failed.loc[hit, "success"] = False
    good = compare(base, plan, "time_to_stop", n_boot=300)
    worse = compare(base, failed, "time_to_stop", n_boot=300)
    assert worse.speedup < good.speedup / 2 and worse.failed_planner == int(hit.sum())


def test_improvement_is_the_papers_formula():
    assert improvement(19.38, 3.71) == pytest.approx(4.2237, abs=1e-4)  # 422.37 %
    assert improvement(19.38, 10.96) == pytest.approx(0.7682, abs=1e-4)  # 76.82 %
    assert improvement(0.77, 0.85) == pytest.approx(-0.0941, abs=1e-4)  # 9.41 % slower


@pytest.mark.parametrize(
    ("quoted", "lo", "hi", "expected"),
    [
        (1.0, 0.8, 1.2, "reproduced"),
        (4.2, 0.8, 1.2, "same direction, smaller effect"),
        (0.3, 0.8, 1.2, "same direction, larger effect"),
        (-0.1, 0.8, 1.2, "reversed"),
        (0.7, -0.1, 0.3, "no clear effect"),
        (-0.1, -0.3, -0.05, "reproduced"),
        (-0.5, -0.3, -0.05, "same direction, smaller effect"),
        (-0.01, -0.3, -0.05, "same direction, larger effect"),
        (0.5, float("nan"), 1.0, "no clear effect"),
    ],
)
def test_verdict_rules(quoted, lo, hi, expected):
    assert verdict(quoted, lo, hi) == expected


def test_paper_tables_agree_with_the_improvements_quoted_in_the_text(repo):
    paper = load_paper_tables(repo / "data/paper/tables.yaml")
    for claim in paper["claims"]:
        col = paper["columns"].index(claim["column"])
        rows = paper["tables"][claim["table"]]["rows"]
        ours = improvement(rows[claim["baseline"]][col][0], rows[claim["planner"]][col][0])
        assert ours == pytest.approx(claim["quoted"], abs=5e-5), claim["text"]
    assert paper["comparable_columns"] == ["random"]
