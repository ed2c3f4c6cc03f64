"""The benchmark-maps statistics and report on a hand-made trial table: solve rates, the
speed-ups over RRT* and against the envelopes (recomputed here by hand: the geometric mean
over queries of the ratio of per-query medians), the clusters (buckets per map, maps pooled),
the random-map speed-ups read from the paper comparison's summary, and the report printing
the summary's own numbers and settings."""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest

from vnrrt.studies.benchmark_maps.report import TAG_LIMIT, build_report, description, ratio
from vnrrt.studies.benchmark_maps.summary import POOLED, analyze, pooled_caution

ENVELOPES = {"vertex": "vnrrt_star~0.5[oracle_vertex@s4]"}
KEYS = ["rrt_star", "vnrrt_star", ENVELOPES["vertex"]]
# (map, bucket) of each query; per key a time factor and whether trial 1 of query 0 fails
QUERIES = [("arena", 1), ("arena", 1), ("arena", 5), ("lak", 2), ("lak", 9), ("lak", 9)]
SETTINGS = {"eps": 0.02, "tau": 0.6, "max_iterations": 5000, "max_seconds": 2.0,
            "level": 0.9, "bootstrap": 300, "seed": 3, "trials": 2, "per_bucket": 1}  # fmt: skip


def _table(queries=QUERIES, keys=KEYS) -> pd.DataFrame:
    """Two trials per (query, configuration): RRT* times t_q and 1.5 t_q, the others faster
    by a factor per query and configuration; RRT*'s second trial of query 0 fails."""
    rng = np.random.default_rng(0)
    rows = []
    for q, (m, bucket) in enumerate(queries):
        base = 0.01 * (q + 1)
        factor = {k: 1.0 / (1.5 + (q + i) % 3) / (1 + 9 * (k in ENVELOPES.values()))
                  for i, k in enumerate(keys)} | {"rrt_star": 1.0}  # fmt: skip
        for key in keys:
            for t in range(2):
                time = base * (1.0 + 0.5 * t) * factor[key] * (1 + 0.01 * rng.random())
                fail = key == "rrt_star" and q == 0 and t == 1
                rows.append({"instance": q, "map_set": m, "cluster": bucket, "key": key,
                             "trial": t, "success": not fail, "time_to_stop": time,
                             "iterations": int(time * 1e5),
                             "fallback_uniform": key == keys[1] and m == "lak"})  # fmt: skip
    return pd.DataFrame(rows)


def _by_hand(table: pd.DataFrame, base: str, plan: str, metric: str) -> float:
    shift = 1.0 if metric == "iterations" else 0.0
    med = table.groupby(["key", "instance"])[metric].median() + shift
    return float(np.exp(np.mean(np.log(med[base] / med[plan]))))


@pytest.fixture(scope="module")
def summary():
    maps = {}
    for m in ("arena", "lak"):
        buckets = sorted({b for n, b in QUERIES if n == m})
        maps[m] = {"width": 9, "height": 9, "buckets": buckets, "queries": 3,
                   "inference_ms": {"vertexnet": 1.0}}  # fmt: skip
    paper = {"over_rrt_star": {"time_to_stop": {"optimal_any_angle": {"vnrrt_star": {"random": {
        "speedup": 1.4, "ci_low": 1.1, "ci_high": 1.7}}}}}}  # fmt: skip
    return analyze(_table(), KEYS, ENVELOPES, maps, SETTINGS, paper)


def _cell(summary, where: str, key: str) -> dict:
    (c,) = [c for c in summary["cells"] if (c["map"], c["configuration"]) == (where, key)]
    return c


@pytest.mark.parametrize("metric", ["time_to_stop", "iterations"])
def test_speedups_over_rrt_star_are_the_geometric_mean_of_median_ratios(summary, metric):
    table = _table()
    for where in ("arena", "lak", POOLED):
        sub = table if where == POOLED else table[table["map_set"] == where]
        for key in KEYS[1:]:
            got = _cell(summary, where, key)[metric]
            assert got["speedup"] == pytest.approx(_by_hand(sub, "rrt_star", key, metric))
            assert got["ci_low"] <= got["speedup"] <= got["ci_high"]


def test_clusters_are_buckets_per_map_and_maps_pooled(summary):
    assert _cell(summary, "arena", "vnrrt_star")["time_to_stop"]["clusters"] == 2  # buckets 1, 5
    assert _cell(summary, "lak", "vnrrt_star")["time_to_stop"]["clusters"] == 2  # buckets 2, 9
    pooled = _cell(summary, POOLED, "vnrrt_star")["time_to_stop"]
    assert (pooled["clusters"], pooled["instances"]) == (2, 6)


def test_solve_rates_count_the_failed_trials(summary):
    assert _cell(summary, "arena", "rrt_star")["solved"] == 5
    assert _cell(summary, "arena", "rrt_star")["solve_rate"] == pytest.approx(5 / 6)
    assert _cell(summary, POOLED, "rrt_star")["trials"] == 12
    assert _cell(summary, "lak", "rrt_star")["solve_rate"] == 1.0
    assert "time_to_stop" not in _cell(summary, POOLED, "rrt_star")  # the baseline
    assert _cell(summary, "lak", "vnrrt_star")["fallbacks"] == 6
    assert _cell(summary, POOLED, "vnrrt_star")["fallbacks"] == 6
    assert _cell(summary, "arena", "vnrrt_star")["fallbacks"] == 0


def test_networks_against_their_envelope_and_in_distribution(summary):
    table = _table()
    (row,) = [r for r in summary["against_envelopes"] if r["map"] == POOLED]
    assert (row["configuration"], row["idea"]) == ("vnrrt_star", "vertex")
    want = _by_hand(table, ENVELOPES["vertex"], "vnrrt_star", "time_to_stop")
    assert row["time_to_stop"]["speedup"] == pytest.approx(want) and want < 1
    (ind,) = summary["in_distribution"]
    assert ind["time_to_stop"]["speedup"] == 1.4
    assert math.isnan(ind["iterations"]["speedup"])  # not in that summary: NaN, not made up


def test_the_report_prints_the_summarys_numbers_and_settings(summary):
    text = build_report(summary, "quick")
    c = _cell(summary, POOLED, "vnrrt_star")
    assert f"| pooled | VNRRT* | 12/12 | {c['median_ms']:.1f} |" in text
    assert ratio(c["time_to_stop"]) in text and ratio(c["iterations"]) in text
    assert "within 2% of the exact optimum" in text and "90% paired bootstrap" in text
    assert "5,000 iterations and 2 s per run" in text and "300 resamples" in text
    assert "| pooled | RRT* | 11/12 |" in text and "vertex envelope" in text
    assert "1.40x [1.10, 1.70]" in text  # the random maps' speed-up beside the real maps'
    assert pooled_caution(2) in text and "1%" not in text and "95%" not in text


def test_the_caution_says_what_few_maps_can_support():
    assert "describes these 3 maps, not maps in general" in pooled_caution(3)
    assert "nothing here speaks for other maps" in pooled_caution(1)
    assert ratio({"speedup": math.nan}) == "n/a"
    assert ratio({"speedup": 2.0, "ci_low": math.nan, "ci_high": 3.0}) == "2.00x"


def test_the_run_description_holds_the_pooled_rows_within_mlflows_tag_limit():
    """Four maps of four buckets and every configuration of the study: the description (an
    MLflow tag) keeps the report's pooled rows and stays under the tag limit."""
    envelopes = {"path": "nrrt_star~0.5[oracle_path@s1]", **ENVELOPES}
    keys = ["rrt_star", "nrrt_star", "vnrrt_star", "m_vnrrt_star@0.5", *envelopes.values()]
    names = ("arena", "lak304d", "64room_000", "losttemple")
    queries = [(m, b) for m in names for b in (10, 40, 80, 120) for _ in range(3)]
    maps = {m: {"width": 512, "height": 512, "buckets": [10, 40, 80, 120], "queries": 12,
                "inference_ms": {"nrrtnet": 300.0, "vertexnet": 300.0}} for m in names}  # fmt: skip
    big = analyze(_table(queries, keys), keys, envelopes, maps, SETTINGS, None)
    text, report = description(big, "cpu"), build_report(big, "cpu")
    assert len(text) < TAG_LIMIT < len(report)
    pooled = [ln for ln in report.splitlines() if ln.startswith("| pooled |")]
    assert len(pooled) == len(keys) + 3 and all(ln in text for ln in pooled[: len(keys)])
    assert pooled_caution(4) in text and "| lak304d |" not in text
