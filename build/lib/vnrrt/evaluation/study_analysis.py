"""Statistics of the oracle study and the regime sweep (:mod:`vnrrt.evaluation.study`),
computed once (stage ``ideas``) as plain JSON-able data for the report and the figures.

Every speed-up is the paired, clustered one of :func:`vnrrt.evaluation.stats.compare`
against RRT* on the same instances (and, in the sweep, in the same cell): the geometric mean
over instances of median(RRT*) / median(planner), with its bootstrap CI.
"""

from __future__ import annotations

import re

import numpy as np
import pandas as pd

from vnrrt.evaluation.stats import compare
from vnrrt.evaluation.table import convergence_column

BASELINE = "rrt_star"
METRICS = ("iterations", "time_to_stop")
EPS_COLUMNS = {0.01: "time_to_stop", 0.02: convergence_column(1.02)}


def _speedup(base: pd.DataFrame, plan: pd.DataFrame, metric: str, n_boot: int, level: float):
    c = compare(base, plan, metric, n_boot=n_boot, level=level)
    return {"speedup": c.speedup, "ci_low": c.ci_low, "ci_high": c.ci_high}


def oracle_table(table: pd.DataFrame, n_boot: int = 2000, level: float = 0.95) -> dict:
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


QUALITY = re.compile(
    r"^(?P<plan>[a-z_]+(@[0-9.]+)?)\[(?P<kind>oracle_[a-z_]+)(@q(?P<q>[0-9.e-]+))?\]$"
)


def quality_curves(oracle: dict, ideas=("oracle_path", "oracle_vertex")) -> pd.DataFrame:
    """The heatmap-quality curve as rows (stop, idea, configuration, q, heat_mass, metric,
    speedup, ci_low, ci_high): one curve per idea and sampler (path; vertex; masked vertex at
    each tau), from the oracle study's summary."""
    rows = []
    for stop, per_key in oracle.items():
        for key, cell in per_key.items():
            m = QUALITY.match(key)
            if m is None or m["kind"] not in ideas:
                continue
            q = float(m["q"]) if m["q"] else 1.0
            for metric in METRICS:
                if metric in cell:
                    rows.append(
                        {
                            "stop": stop,
                            "idea": m["kind"],
                            "configuration": m["plan"],
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


def regime_table(table: pd.DataFrame, n_boot: int = 2000, level: float = 0.95) -> pd.DataFrame:
    """Per regime cell, stop rule, eps and configuration: the paired time speed-up over RRT*
    in the same cell, and the success rate. eps 0.02 uses the 1.02 x reference time of the
    same runs (a run that never got there: its stop time, censored)."""
    rows = []
    for (regime, stop), sub in table.groupby(["regime", "stop"], sort=False):
        base = sub[sub["key"] == BASELINE]
        for eps, col in EPS_COLUMNS.items():
            b = _as_metric(base, col)
            for key, plan in sub.groupby("key", sort=False):
                if key == BASELINE:
                    continue
                s = _speedup(b, _as_metric(plan, col), "time_to_stop", n_boot, level)
                rows.append(
                    {
                        "regime": regime,
                        "stop": stop,
                        "eps": eps,
                        "configuration": key,
                        "success_rate": float(plan["success"].mean()),
                        "baseline_success_rate": float(base["success"].mean()),
                        "median_ms": float(1e3 * plan[col].fillna(plan["time_to_stop"]).median()),
                        **s,
                    }
                )
    return pd.DataFrame(rows)


def _as_metric(rows: pd.DataFrame, col: str) -> pd.DataFrame:
    """``rows`` with ``time_to_stop`` replaced by ``col`` (censored at the stop time)."""
    if col == "time_to_stop":
        return rows
    return rows.assign(time_to_stop=rows[col].fillna(rows["time_to_stop"]))


CLAIMS = (
    ("vnrrt_star", "nrrt_star", "VNRRT* faster than NRRT*"),
    ("m_vnrrt_star@0.5", "nrrt_star", "M-VNRRT* (tau=0.5) faster than NRRT*"),
    ("vnrrt_star", "rrt_star", "VNRRT* faster than RRT*"),
)


def regime_claims(table: pd.DataFrame, n_boot: int = 2000, level: float = 0.95) -> list[dict]:
    """For each of the paper's optimal-solution claims (:data:`CLAIMS`) and each
    (stop, eps): in which regime cells its sign holds (CI above 1), is reversed (below 1) or
    shows no clear effect."""
    out = []
    for plan_key, base_key, text in CLAIMS:
        for stop in ("optimal", "optimal_any_angle"):
            for eps, col in EPS_COLUMNS.items():
                holds, reversed_, unclear = [], [], []
                for regime, sub in table[table["stop"] == stop].groupby("regime", sort=False):
                    base, plan = sub[sub["key"] == base_key], sub[sub["key"] == plan_key]
                    if base.empty or plan.empty:
                        continue
                    s = _speedup(
                        _as_metric(base, col), _as_metric(plan, col), "time_to_stop", n_boot, level
                    )
                    bucket = (
                        holds if s["ci_low"] > 1 else reversed_ if s["ci_high"] < 1 else unclear
                    )
                    bucket.append(regime)
                if holds or reversed_ or unclear:
                    out.append(
                        {
                            "claim": text,
                            "planner": plan_key,
                            "baseline": base_key,
                            "stop": stop,
                            "eps": eps,
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
    n_boot: int = 2000,
    level: float = 0.95,
) -> dict:
    """The whole summary of the oracle study and the regime sweep."""
    summary = oracle_table(oracle, n_boot, level)
    curves = quality_curves(summary)
    placed = networks_on_curve(summary, network_keys)
    cells = regime_table(regime, n_boot, level) if len(regime) else pd.DataFrame()
    return {
        "oracle": summary,
        "curves": curves.replace({np.nan: None}).to_dict("records"),
        "networks": placed.replace({np.nan: None}).to_dict("records"),
        "regime": cells.replace({np.nan: None}).to_dict("records"),
        "regime_claims": regime_claims(regime, n_boot, level) if len(regime) else [],
        "instances": int(oracle["instance"].nunique()),
        "regime_instances": int(regime["instance"].nunique()) if len(regime) else 0,
    }
