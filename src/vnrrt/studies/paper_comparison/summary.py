"""Everything the report says, computed once from the merged trial table (stage
``evaluate``): per-cell summaries, paired speed-ups, the paper's claims with verdicts and
convergence curves. The result is plain JSON-able data (``paths.summary``,
``data/<scale>/summary.json``); :mod:`vnrrt.studies.paper_comparison.report` only
renders it.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from vnrrt.evaluation.keys import ConfigKey
from vnrrt.evaluation.noise import timing_noise
from vnrrt.evaluation.protocol import STOPS
from vnrrt.evaluation.stats import Summary, compare, summarize
from vnrrt.evaluation.strata import assign, mix
from vnrrt.evaluation.table import CONVERGENCE_COLUMNS, CONVERGENCE_FACTORS, solved
from vnrrt.studies.paper_comparison.claims import claims, mask_shares

METRICS = {"time_to_stop": True, "iterations": True, "cost": False}  # metric -> censored


def _summary(sub: pd.DataFrame, metric: str, n_boot: int, level: float) -> Summary:
    return summarize(
        sub[metric],
        solved(sub, metric),
        sub["cluster"],
        sub["fallback_uniform"],
        censor=METRICS[metric],
        n_boot=n_boot,
        level=level,
    )


def cells(table: pd.DataFrame, n_boot: int, level: float) -> dict:
    """``{stop: {key: {map_set: {metric: Summary dict}}}}`` for time, iterations and cost."""
    out: dict = {}
    for (stop, key, map_set), sub in table.groupby(["stop", "key", "map_set"], sort=False):
        out.setdefault(stop, {}).setdefault(key, {})[map_set] = {
            m: _summary(sub, m, n_boot, level).as_dict() for m in METRICS
        }
    return out


def speedups(
    table: pd.DataFrame,
    baseline: str,
    metric: str,
    n_boot: int,
    level: float,
) -> dict:
    """``{stop: {key: {map_set: Comparison dict}}}`` of every configuration against
    ``baseline`` on the same instances."""
    out: dict = {}
    for (stop, map_set), sub in table.groupby(["stop", "map_set"], sort=False):
        base = sub[sub["key"] == baseline]
        if base.empty:
            continue
        for key, plan in sub.groupby("key", sort=False):
            if key != baseline:
                c = compare(base, plan, metric, n_boot=n_boot, level=level)
                out.setdefault(stop, {}).setdefault(key, {})[map_set] = c.as_dict()
    return out


def convergence_curves(table: pd.DataFrame, eps: float) -> pd.DataFrame:
    """Median time (s) at which the best cost first fell to ``factor`` x reference, per
    optimal stop rule, configuration and map set, over all trials; a bound a trial never
    reached enters at the trial's stop time (censored, a lower bound). The last point,
    factor ``1 + eps``, is the stop rule (factors at or below it are reached at the stop or
    never, and left out). Columns: stop, planner, map_set, factor, median_time."""
    rows = []
    opt = table[table["stop"] != "initial"]
    for (stop, key, map_set), sub in opt.groupby(["stop", "key", "map_set"], sort=False):
        stop_t = sub["time_to_stop"].to_numpy()
        cols = [*CONVERGENCE_COLUMNS, "time_to_stop"]
        for f, col in zip([*CONVERGENCE_FACTORS, 1.0 + eps], cols, strict=True):
            if f <= 1.0 + eps and col != "time_to_stop":
                continue
            t = sub[col].to_numpy()
            median = float(np.median(np.where(np.isnan(t), stop_t, t)))
            rows.append(
                {
                    "stop": stop,
                    "planner": key,
                    "map_set": map_set,
                    "factor": f,
                    "median_time": median,
                }
            )
    return pd.DataFrame(rows, columns=["stop", "planner", "map_set", "factor", "median_time"])


def informed_comparisons(table: pd.DataFrame, n_boot: int, level: float) -> dict:
    """``{stop: {key: {metric: {"vs_informed_rrt": ..., "vs_uninformed": ...}}}}``: each
    informed configuration on the random instances against Informed RRT* (does the learned
    sampler help on top of informed sampling?) and against itself without informed sampling
    (what informed sampling adds). Paired comparisons (:func:`compare`)."""
    out: dict = {}
    rand = table[table["map_set"] == "random"]
    base_key = ConfigKey("rrt_star", informed=True).text
    for stop, sub in rand.groupby("stop", sort=False):
        keys = [k for k in dict.fromkeys(sub["key"]) if ConfigKey.parse(k).informed]
        base = sub[sub["key"] == base_key]
        for key in keys:
            plan = sub[sub["key"] == key]
            plain = sub[sub["key"] == ConfigKey.parse(key).with_informed(False).text]
            cell = {}
            for m in ("time_to_stop", "iterations"):
                vs = {}
                if key != base_key and not base.empty:
                    vs["vs_informed_rrt"] = compare(
                        base, plan, m, n_boot=n_boot, level=level
                    ).as_dict()
                if not plain.empty:
                    vs["vs_uninformed"] = compare(
                        plain, plan, m, n_boot=n_boot, level=level
                    ).as_dict()
                cell[m] = vs
            out.setdefault(stop, {})[key] = cell
    return out


def with_inference(table: pd.DataFrame, inference_ms: dict[str, float]) -> pd.DataFrame:
    """``table`` with ``time_total``: planning time plus the network's inference per map (s,
    ``inference_ms``: network -> ms; 0 for RRT* and oracles)."""
    extra = table["source"].map(lambda s: inference_ms.get(s, 0.0) / 1e3)
    return table.assign(time_total=table["time_to_stop"] + extra)


def analyze(
    table: pd.DataFrame,
    paper: dict,
    eps: float,
    st,
    inference_ms: dict[str, float],
    turns: dict[int, int] | None = None,
) -> dict:
    """The whole summary (module doc) of a merged trial table, with the settings its numbers
    were computed with (stop tolerance ``eps``; ``st``, the ``stats`` section: resamples, CI
    level, claim rules, strata); ``inference_ms``: each network's inference per map (ms);
    ``turns``: each instance's turning points (:mod:`vnrrt.evaluation.strata`; None: no
    strata)."""
    n_boot, level = st.bootstrap, st.level
    stops = [s for s in STOPS if s in set(table["stop"])]
    keys = list(dict.fromkeys(table["key"]))
    shares = mask_shares(table)
    timed = with_inference(table, inference_ms)
    strata = None if turns is None else assign(turns, st.strata)
    judged = claims(timed, paper, st, shares, strata)
    noise = timing_noise(table, judged["bootstrap"], judged["corrected_level"])
    return {
        "eps": eps,
        "level": level,
        "bootstrap": n_boot,
        "inference_ms": dict(inference_ms),
        "mask_shares": shares,
        "stops": stops,
        "keys": keys,
        "map_sets": list(dict.fromkeys(table["map_set"])),
        "cells": cells(table, n_boot, level),
        "over_rrt_star": {
            m: speedups(timed, "rrt_star", m, n_boot, level)
            for m in ("time_to_stop", "iterations", "time_total")
        },
        "over_nrrt_star": {
            m: speedups(table, "nrrt_star", m, n_boot, level)
            for m in ("time_to_stop", "iterations")
        },
        "claims": judged,
        "strata": {} if strata is None else mix(table, strata, st.strata),
        "informed": informed_comparisons(table, n_boot, level),
        "setup_ms": {
            k: float(1e3 * sub["setup_time"].median())
            for k, sub in table.groupby("key", sort=False)
        },
    } | ({"timing_noise": noise} if noise else {})
