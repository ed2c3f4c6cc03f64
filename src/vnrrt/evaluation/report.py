"""``paper_comparison.md``: the paper's Tables 1-3 beside ours, row by row, with verdicts.

Input: a per-trial table (one row per planner run; columns :data:`TRIAL_COLUMNS`) and
the paper's numbers (``reports/paper/tables.yaml``: data, never typed in here). Our cells
show mean±std as the paper prints them, then the median, the 95 % bootstrap CI of the
mean and the success rate; statistics use successful trials only.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
import yaml

from vnrrt.evaluation.stats import fmt_mean_std, improvement_ci, summarize, verdict

TRIAL_COLUMNS = (
    "planner",  # rrt_star | nrrt_star | vnrrt_star | m_vnrrt_star | ...
    "tau",  # mask threshold (NaN when unused)
    "map_set",  # map_1 .. map_5 | random
    "map",  # map identifier inside the set
    "trial",  # trial index
    "stop",  # initial | optimal
    "success",  # bool: stop rule met within the budgets
    "cost",  # path length (px)
    "iterations",
    "tree_size",
    "collision_checks",
    "time_to_first",  # s
    "time_to_stop",  # s
)


def planner_key(planner: str, tau: float | None) -> str:
    """Row key of a planner configuration: ``m_vnrrt_star@0.5`` or ``vnrrt_star``."""
    if tau is None or (isinstance(tau, float) and np.isnan(tau)):
        return planner
    return f"{planner}@{tau:g}"


def load_paper_tables(path: str | Path) -> dict:
    """The paper's numbers (see ``reports/paper/tables.yaml``)."""
    with open(path) as f:
        return yaml.safe_load(f)


def check_trials(trials: pd.DataFrame) -> pd.DataFrame:
    """Validate the trial table's columns and add the ``key`` column (:func:`planner_key`)."""
    missing = [c for c in TRIAL_COLUMNS if c not in trials.columns]
    if missing:
        raise ValueError(f"trial table lacks columns {missing}")
    out = trials.copy()
    out["key"] = [planner_key(p, t) for p, t in zip(out["planner"], out["tau"])]
    out["success"] = out["success"].astype(bool)
    return out


def _cell(sub: pd.DataFrame, metric: str) -> str:
    """Our statistics, to 3 significant digits (our planners run in milliseconds)."""
    if sub.empty:
        return "—"
    s = summarize(sub[metric].to_numpy(), sub["success"].to_numpy())
    if s.successes == 0:
        return f"no success (0/{s.n})"
    return (
        f"{s.mean:.3g}±{s.std:.2g}<br>med {s.median:.3g} "
        f"[{s.ci_low:.3g}, {s.ci_high:.3g}]<br>{s.successes}/{s.n} ok"
    )


def table_markdown(trials: pd.DataFrame, spec: dict, columns: list[str], metric: str) -> str:
    """One paper table as markdown: per planner a 'paper' row and an 'ours' row."""
    rows = spec.get("rows", {})
    keys = list(rows) + sorted(set(trials["key"]) - set(rows))
    head = "| planner | source | " + " | ".join(columns) + " |"
    lines = [head, "|" + " --- |" * (len(columns) + 2)]
    for key in keys:
        if key in rows and metric == spec["metric"]:
            cells = [fmt_mean_std(m, s) for m, s in rows[key]]
            lines.append(f"| {key} | paper | " + " | ".join(cells) + " |")
        ours = [_cell(trials[(trials["key"] == key) & (trials["map_set"] == c)], metric)
                for c in columns]  # fmt: skip
        lines.append(f"| {key} | ours | " + " | ".join(ours) + " |")
    if "optimal" in spec and metric == spec["metric"]:
        optimum = " | ".join(f"{v:.2f}" for v in spec["optimal"])
        lines.append(f"| A* optimum | paper | {optimum} |")
    return "\n".join(lines)


def claim_rows(trials: pd.DataFrame, paper: dict) -> list[dict]:
    """Each quoted improvement of the paper against ours (time and iterations), with CI."""
    out = []
    for claim in paper["claims"]:
        spec = paper["tables"][claim["table"]]
        sel = (trials["stop"] == spec["stop"]) & (trials["map_set"] == claim["column"])
        base = trials[sel & (trials["key"] == claim["baseline"]) & trials["success"]]
        plan = trials[sel & (trials["key"] == claim["planner"]) & trials["success"]]
        row = {**claim}
        for metric in ("time_to_stop", "iterations"):
            if base.empty or plan.empty:
                row[metric] = None
                continue
            imp, lo, hi = improvement_ci(base[metric].to_numpy(), plan[metric].to_numpy())
            row[metric] = {"ours": imp, "ci": [lo, hi], "verdict": verdict(claim["quoted"], lo, hi)}
        out.append(row)
    return out


def _claim_markdown(rows: list[dict]) -> str:
    head = "| claim | paper | ours (time) | verdict (time) | ours (iterations) | verdict (iter.) |"
    lines = [head, "| --- | --- | --- | --- | --- | --- |"]
    for r in rows:
        cells = []
        for metric in ("time_to_stop", "iterations"):
            m = r[metric]
            if m is None:
                cells += ["no data", "—"]
            else:
                lo, hi = m["ci"]
                cells += [f"{m['ours']:+.1%} [{lo:+.1%}, {hi:+.1%}]", m["verdict"]]
        lines.append(f"| {r['text']} | {r['quoted']:+.2%} | " + " | ".join(cells) + " |")
    return "\n".join(lines)


def build_report(trials: pd.DataFrame, paper: dict) -> str:
    """The whole ``paper_comparison.md`` text."""
    trials = check_trials(trials)
    cols = paper["columns"]
    parts = ["# VertexNet RRT*: the paper's tables beside this reproduction", "",
             "Ours: mean±std (as the paper), median [95% bootstrap CI of the mean], successful "
             "trials / trials. Statistics over successful trials.", ""]  # fmt: skip
    for spec in paper["tables"].values():
        sub = trials[trials["stop"] == spec["stop"]]
        parts += [f"## {spec['title']}", "", table_markdown(sub, spec, cols, spec["metric"]), ""]
    strict = trials[trials["stop"] == "optimal_any_angle"]
    if not strict.empty:
        spec = {"title": "Table 3, stricter: time to within 1% of the any-angle length (s; "
                "ours, not in the paper)", "metric": "time_to_stop"}  # fmt: skip
        parts += [f"## {spec['title']}", "", table_markdown(strict, spec, cols, "time_to_stop"), ""]
    for stop in ("initial", "optimal", "optimal_any_angle"):
        sub = trials[trials["stop"] == stop]
        if not sub.empty:
            spec = {"title": f"Iterations, stop rule {stop} (ours; not in the paper)",
                    "metric": "iterations"}  # fmt: skip
            parts += [f"## {spec['title']}", "", table_markdown(sub, spec, cols, "iterations"), ""]
    note = ("Improvement = mean(baseline) / mean(planner) - 1, as the paper computes it; "
            "verdict from the 95% bootstrap CI.")  # fmt: skip
    claims = _claim_markdown(claim_rows(trials, paper))
    parts += ["## The paper's quoted improvements", "", note, "", claims]
    return "\n".join(parts) + "\n"
