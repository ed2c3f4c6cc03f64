"""Statistics of the oracle study and the regime sweep
(:mod:`vnrrt.evaluation.sampling_ideas.design`), computed once (stage ``ideas``) as plain
JSON-able data (``paths.ideas_summary``) for the report and the figures.

Every speed-up is the paired, clustered one of :func:`vnrrt.evaluation.stats.compare`
against RRT* on the same instances (and, in the sweep, in the same cell): the geometric mean
over instances of median(RRT*) / median(planner), with its bootstrap CI.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from vnrrt.evaluation.keys import ConfigKey, label
from vnrrt.evaluation.sampling_ideas.design import QUALITY_IDEAS
from vnrrt.evaluation.sources import is_oracle, parse_source
from vnrrt.evaluation.stats import compare

BASELINE = "rrt_star"
METRICS = ("iterations", "time_to_stop")


def _speedup(base: pd.DataFrame, plan: pd.DataFrame, metric: str, n_boot: int, level: float):
    c = compare(base, plan, metric, n_boot=n_boot, level=level)
    return {"speedup": c.speedup, "ci_low": c.ci_low, "ci_high": c.ci_high}


def oracle_table(table: pd.DataFrame, n_boot: int, level: float) -> dict:
    """``{stop: {key: {success_rate, median_ms, median_iterations, heat_mass, iterations,
    time_to_stop}}}``: per configuration and stop rule, against RRT* (speed-ups with CIs)."""
    out: dict = {}
    for stop, sub in table.groupby("stop", sort=False):
        base = sub[sub["key"] == BASELINE]
        for key, rows in sub.groupby("key", sort=False):
            cell = {
                "success_rate": float(rows["success"].mean()),
                "median_ms": float(1e3 * rows["time_to_stop"].median()),
                "median_iterations": float(rows["iterations"].median()),
                "heat_mass": float(rows["heat_mass"].mean()),
            }
            if key != BASELINE and not base.empty:
                for m in METRICS:
                    cell[m] = _speedup(base, rows, m, n_boot, level)
            out.setdefault(stop, {})[key] = cell
    return out


def quality_curves(oracle: dict, ideas=QUALITY_IDEAS) -> pd.DataFrame:
    """The heatmap-quality curve as rows (stop, idea, configuration, q, heat_mass, metric,
    speedup, ci_low, ci_high): one curve per idea and sampler (path; vertex; masked vertex at
    each tau), from the oracle study's summary; ``configuration`` is the sampler's key text
    without its source."""
    rows = []
    for stop, per_key in oracle.items():
        for text, cell in per_key.items():
            key = ConfigKey.parse(text)
            if not (key.named_source and is_oracle(key.source)) or key.informed:
                continue
            kind, q = parse_source(key.source)
            if kind not in ideas:
                continue
            plain = ConfigKey(key.planner, key.tau).text
            for metric in METRICS:
                if metric in cell:
                    rows.append(
                        {
                            "stop": stop,
                            "idea": kind,
                            "configuration": plain,
                            "q": q,
                            "heat_mass": cell["heat_mass"],
                            "metric": metric,
                            **cell[metric],
                        }
                    )
    cols = [
        "stop",
        "idea",
        "configuration",
        "q",
        "heat_mass",
        "metric",
        "speedup",
        "ci_low",
        "ci_high",
    ]
    return pd.DataFrame(rows, columns=cols)


def networks_on_curve(oracle: dict, keys: list[str]) -> pd.DataFrame:
    """Where the trained configurations ``keys`` sit: their heatmaps' mass near their
    target and their speed-ups, in the oracle study's table."""
    rows = []
    for stop, per_key in oracle.items():
        for key in keys:
            cell = per_key.get(key)
            for metric in METRICS:
                if cell is not None and metric in cell:
                    rows.append(
                        {
                            "stop": stop,
                            "configuration": key,
                            "metric": metric,
                            "heat_mass": cell["heat_mass"],
                            **cell[metric],
                        }
                    )
    return pd.DataFrame(
        rows,
        columns=["stop", "configuration", "metric", "heat_mass", "speedup", "ci_low", "ci_high"],
    )


def regime_table(table: pd.DataFrame, n_boot: int, level: float) -> pd.DataFrame:
    """Per regime cell, stop rule and configuration: the paired time speed-up over RRT* in
    the same cell, and the success rates."""
    rows = []
    for (regime, stop), sub in table.groupby(["regime", "stop"], sort=False):
        base = sub[sub["key"] == BASELINE]
        for key, plan in sub.groupby("key", sort=False):
            if key == BASELINE:
                continue
            rows.append(
                {
                    "regime": regime,
                    "stop": stop,
                    "configuration": key,
                    "success_rate": float(plan["success"].mean()),
                    "baseline_success_rate": float(base["success"].mean()),
                    "median_ms": float(1e3 * plan["time_to_stop"].median()),
                    **_speedup(base, plan, "time_to_stop", n_boot, level),
                }
            )
    return pd.DataFrame(rows)


def regime_claims(
    table: pd.DataFrame, pairs: list[tuple[str, str]], n_boot: int, level: float
) -> list[dict]:
    """For each (planner, baseline) key pair of the paper's optimal-solution claims
    (:func:`vnrrt.evaluation.paper_tables.claim_pairs`) and each optimal stop rule: in which
    regime cells its sign holds (CI above 1), is reversed (below 1) or shows no clear
    effect."""
    out = []
    for plan_key, base_key in pairs:
        text = f"{label(plan_key)} faster than {label(base_key)}"
        for stop in ("optimal", "optimal_any_angle"):
            holds, reversed_, unclear = [], [], []
            for regime, sub in table[table["stop"] == stop].groupby("regime", sort=False):
                base, plan = sub[sub["key"] == base_key], sub[sub["key"] == plan_key]
                if base.empty or plan.empty:
                    continue
                s = _speedup(base, plan, "time_to_stop", n_boot, level)
                bucket = holds if s["ci_low"] > 1 else reversed_ if s["ci_high"] < 1 else unclear
                bucket.append(regime)
            if holds or reversed_ or unclear:
                out.append(
                    {
                        "claim": text,
                        "planner": plan_key,
                        "baseline": base_key,
                        "stop": stop,
                        "holds": holds,
                        "reversed": reversed_,
                        "unclear": unclear,
                    }
                )
    return out


def analyze_study(
    oracle: pd.DataFrame,
    regime: pd.DataFrame,
    network_keys: list[str],
    claim_pairs: list[tuple[str, str]],
    settings: dict,
) -> dict:
    """The whole summary of the oracle study and the regime sweep; ``claim_pairs`` as
    :func:`regime_claims` takes them; ``settings`` (kept in the summary for its readers) holds
    at least ``bootstrap`` (resamples) and ``level`` (of the CIs)."""
    n_boot, level = int(settings["bootstrap"]), float(settings["level"])
    summary = oracle_table(oracle, n_boot, level)
    curves = quality_curves(summary)
    placed = networks_on_curve(summary, network_keys)
    cells = regime_table(regime, n_boot, level) if len(regime) else pd.DataFrame()
    return {
        "settings": settings,
        "oracle": summary,
        "curves": curves.replace({np.nan: None}).to_dict("records"),
        "networks": placed.replace({np.nan: None}).to_dict("records"),
        "regime": cells.replace({np.nan: None}).to_dict("records"),
        "regime_claims": regime_claims(regime, claim_pairs, n_boot, level) if len(regime) else [],
        "instances": int(oracle["instance"].nunique()),
        "regime_instances": int(regime["instance"].nunique()) if len(regime) else 0,
    }
