"""The paper's Tables 1-3 beside ours in ``paper_comparison.md``: one cell per (configuration,
map set, metric), the optimal lengths, the paired speed-ups and the informed variants. A
renderer only: every number comes from the summary
(:func:`vnrrt.studies.paper_comparison.summary.analyze`) or the paper's ``tables.yaml``."""

from __future__ import annotations

import math

from vnrrt.evaluation.keys import is_informed, label, sort_texts
from vnrrt.names import MAP_SET_NAMES as COLUMN_NAMES
from vnrrt.names import stop_title
from vnrrt.studies.paper_comparison.networks_report import num as _num


def cell(s: dict | None, scale: float = 1.0) -> str:
    """One of our cells: ``median (mean±std) ok/n``, ``>=`` on censored values, with budget
    hits and sampler fallbacks when there were any."""
    if s is None:
        return "—"
    if not math.isfinite(s["mean"]):
        return f"no success (0/{s['n']})"
    med = ("" if s["median_exact"] else ">=") + _num(s["median"] * scale)
    mean = ("" if not s["censored"] else ">=") + _num(s["mean"] * scale)
    out = f"{med} ({mean}±{_num(s['std'] * scale, 2)}) {s['successes']}/{s['n']}"
    if s["fallbacks"]:
        out += f", fallback {s['fallbacks']}"
    return out


def _paper(mean_std) -> str:
    m, s = mean_std
    return f"{m:.2f}±{s:.2f}"


def table(summary: dict, spec: dict, columns: list[str], metric: str, unit: float = 1.0) -> str:
    """One table as markdown: per configuration a ``paper`` row (when the paper has one for
    this metric) and an ``ours`` row."""
    stop = spec["stop"]
    rows = spec.get("rows", {}) if metric == spec.get("metric") else {}
    ours = summary["cells"].get(stop, {})
    paper_keys = [k for k in sort_texts(summary["keys"]) if not is_informed(k)]
    keys = list(rows) + [k for k in paper_keys if k not in rows]
    lines = [
        "| configuration | source | " + " | ".join(COLUMN_NAMES.get(c, c) for c in columns) + " |",
        "|" + " --- |" * (len(columns) + 2),
    ]
    for key in keys:
        if key in rows:
            lines.append(
                f"| {label(key)} | paper | " + " | ".join(_paper(v) for v in rows[key]) + " |"
            )
        if key in ours:
            got = [cell(ours[key].get(c, {}).get(metric), unit) for c in columns]
            lines.append(f"| {label(key)} | ours | " + " | ".join(got) + " |")
    return "\n".join(lines)


def optima_table(paper: dict, optima: dict) -> str:
    """Per map set: the paper's optimal length, our A* optimum and exact optimum."""
    cols = paper["columns"]
    opt = paper["tables"]["initial_path_length"].get("optimal", [])
    head = "| | " + " | ".join(COLUMN_NAMES.get(c, c) for c in cols) + " |"
    lines = [head, "|" + " --- |" * (len(cols) + 1)]
    lines.append("| paper: optimal length | " + " | ".join(f"{v:.2f}" for v in opt) + " |")
    for name, field in (
        ("ours: A* optimum", "astar"),
        ("ours: exact continuous optimum", "exact"),
        ("ours: taut A* path (approximation)", "taut"),
    ):
        vals = [optima.get(c, {}).get(field) for c in cols]
        lines.append(f"| {name} | " + " | ".join(_num(v, 5) for v in vals) + " |")
    return "\n".join(lines)


def speedup_table(speedups: dict, stop: str, columns: list[str]) -> str:
    """Paired speed-ups (gm ratio of medians [CI]) of every configuration over a baseline."""
    per_key = speedups.get(stop, {})
    lines = [
        "| configuration | " + " | ".join(COLUMN_NAMES.get(c, c) for c in columns) + " |",
        "|" + " --- |" * (len(columns) + 1),
    ]
    for key, sets in per_key.items():
        if is_informed(key):
            continue  # their own section
        vals = []
        for c in columns:
            s = sets.get(c)
            vals.append(
                "—" if s is None else f"{s['speedup']:.2f}x [{s['ci_low']:.2f}, {s['ci_high']:.2f}]"
            )
        lines.append(f"| {label(key)} | " + " | ".join(vals) + " |")
    return "\n".join(lines)


def informed_section(summary: dict) -> str:
    """Informed variants on the random instances: medians, and paired speed-ups against
    Informed RRT* and against the same configuration without informed sampling."""
    parts = []
    for stop, per_key in summary.get("informed", {}).items():
        cells = summary["cells"].get(stop, {})
        lines = [
            f"### {stop_title(stop, summary['eps'])}",
            "",
            "| configuration | median ms | median iterations | time vs Informed RRT* | "
            "iterations vs Informed RRT* | time vs not informed |",
            "|" + " --- |" * 6,
        ]
        for key in sort_texts(per_key):
            c = cells.get(key, {}).get("random", {})
            t, it = c.get("time_to_stop"), c.get("iterations")
            vs = per_key[key]
            lines.append(
                f"| {label(key)} | {_num(1e3 * t['median']) if t else '—'} | "
                f"{_num(it['median']) if it else '—'} | "
                f"{_speed(vs['time_to_stop'].get('vs_informed_rrt'))} | "
                f"{_speed(vs['iterations'].get('vs_informed_rrt'))} | "
                f"{_speed(vs['time_to_stop'].get('vs_uninformed'))} |"
            )
        parts += ["\n".join(lines), ""]
    return "\n".join(parts)


def _speed(c: dict | None) -> str:
    if not c:
        return "—"
    return f"{c['speedup']:.2f}x [{c['ci_low']:.2f}, {c['ci_high']:.2f}]"


def shorter_range(optima: dict) -> str:
    """How much shorter the exact optimum is than the A* optimum, over the map sets:
    ``2-8%``."""
    gaps = [1 - o["exact"] / o["astar"] for o in optima.values() if o.get("astar")]
    if not gaps:
        return "n/a"
    lo, hi = math.floor(100 * min(gaps)), math.ceil(100 * max(gaps))
    return f"{lo}%" if lo == hi else f"{lo}-{hi}%"
