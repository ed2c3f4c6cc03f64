"""``reports/sampling_ideas.md``: what each sampling idea can give (oracle heatmaps, the
heatmap-quality curve, the planner regime) and a conclusion computed from the numbers.
A renderer of :func:`vnrrt.evaluation.sampling_ideas.summary.analyze_study`'s summary; every
setting it names (tolerance, CI level, mass radius, blur) comes from the summary's
``settings``, the run's config."""

from __future__ import annotations

import math

import pandas as pd

from vnrrt.evaluation.keys import label, sort_texts
from vnrrt.names import level_name, percent, stop_name


def _x(s: dict | None) -> str:
    if not s or s.get("speedup") is None or not math.isfinite(s["speedup"]):
        return "—"
    return f"{s['speedup']:.2f}x [{s['ci_low']:.2f}, {s['ci_high']:.2f}]"


def _pct(v) -> str:
    return "—" if v is None or not math.isfinite(v) else f"{100 * v:.1f}%"


def oracle_section(oracle: dict, stop: str) -> str:
    """Per configuration: success, medians, heatmap mass near target, speed-ups over RRT*."""
    per_key = oracle.get(stop, {})
    keys = [k for k in sort_texts(per_key) if "@q" not in k]
    lines = [
        "| configuration | success | median ms | median iterations | mass near target | "
        "speed-up, iterations | speed-up, time |",
        "|" + " --- |" * 7,
    ]
    for key in keys:
        c = per_key[key]
        lines.append(
            f"| {label(key)} | {_pct(c['success_rate'])} | {c['median_ms']:.3g} "
            f"| {c['median_iterations']:.0f} | {_pct(c['heat_mass'])} | "
            f"{_x(c.get('iterations'))} | {_x(c.get('time_to_stop'))} |"
        )
    return "\n".join(lines)


def curve_table(curves: pd.DataFrame, stop: str, metric: str = "iterations") -> str:
    """The quality curve as a table: rows q, columns the idea/sampler pairs."""
    sub = curves[(curves["stop"] == stop) & (curves["metric"] == metric)]
    if sub.empty:
        return "(not run)"
    series = list(dict.fromkeys(zip(sub["idea"], sub["configuration"], strict=True)))
    head = "| q | " + " | ".join(f"{label(c)} [{i}]" for i, c in series) + " |"
    lines = [head, "|" + " --- |" * (len(series) + 1)]
    for q in sorted(set(sub["q"]), reverse=True):
        cells = []
        for idea, conf in series:
            row = sub[(sub["q"] == q) & (sub["idea"] == idea) & (sub["configuration"] == conf)]
            if row.empty:
                cells.append("—")
                continue
            r = row.iloc[0].to_dict()
            cells.append(f"{_x(r)} (mass {_pct(r['heat_mass'])})")
        lines.append(f"| {q:g} | " + " | ".join(cells) + " |")
    return "\n".join(lines)


def break_even(curves: pd.DataFrame, stop: str, metric: str = "iterations") -> dict[str, float]:
    """Per idea/sampler: the smallest heatmap mass near target at which the speed-up's CI
    lies above 1 at that mass and at every better one (NaN: never)."""
    out = {}
    sub = curves[(curves["stop"] == stop) & (curves["metric"] == metric)]
    for (idea, conf), rows in sub.groupby(["idea", "configuration"], sort=False):
        rows = rows.sort_values("heat_mass", ascending=False)
        mass = math.nan
        for _, r in rows.iterrows():
            if r["ci_low"] is not None and r["ci_low"] > 1:
                mass = r["heat_mass"]
            else:
                break
        out[f"{label(conf)} [{idea}]"] = mass
    return out


def conclusion(summary: dict) -> list[str]:
    """Plain-language findings computed from the summary (module doc)."""
    oracle, out = summary["oracle"], []
    eps, radius = summary["settings"]["eps"], summary["settings"]["radius"]
    for stop in ("optimal", "optimal_any_angle"):
        out += _oracle_findings(oracle.get(stop, {}), stop_name(stop, eps))
    curves = pd.DataFrame(summary["curves"])
    nets = pd.DataFrame(summary["networks"])
    if not curves.empty:
        need = break_even(curves, "optimal")
        said = [
            f"{k}: {_pct(v)}" if math.isfinite(v) else f"{k}: never at these q"
            for k, v in need.items()
        ]
        out.append(
            "Heatmap quality needed for a clear gain over RRT* in iterations, "
            f"{stop_name('optimal', eps)} (mass within {radius:g} px of the target at which "
            "the CI leaves 1): " + "; ".join(said) + "."
        )
    if not nets.empty:
        sub = nets[(nets["stop"] == "optimal") & (nets["metric"] == "iterations")]
        placed = [
            f"{label(r['configuration'])} {_pct(r['heat_mass'])} ({_x(r.to_dict())})"
            for _, r in sub.iterrows()
        ]
        out.append("The trained networks sit at: " + "; ".join(placed) + ".")
    for c in summary["regime_claims"]:
        n = len(c["holds"]) + len(c["reversed"]) + len(c["unclear"])
        text = (
            f"{c['claim']} ({stop_name(c['stop'], eps)}): holds in {len(c['holds'])} of {n} "
            f"regime cells, reversed in {len(c['reversed'])}, unclear in "
            f"{len(c['unclear'])}"
        )
        if c["holds"]:
            text += f" (holds: {', '.join(c['holds'][:6])}{' ...' if len(c['holds']) > 6 else ''})"
        out.append(text + ".")
    return out


def _oracle_findings(per: dict, stop_text: str) -> list[str]:
    """The oracle study's findings at one stop rule (``per``: its cells by key)."""
    out = []
    path, vert = per.get("nrrt_star[oracle_path]"), per.get("vnrrt_star[oracle_vertex]")
    if path and vert and "iterations" in path and "iterations" in vert:
        p, v = path["iterations"], vert["iterations"]
        if v["ci_low"] > p["ci_high"]:
            word = "fewer iterations than"
        elif v["ci_high"] < p["ci_low"]:
            word = "more iterations than"
        else:
            word = "no clear difference in iterations from"
        out.append(
            f"With perfect heatmaps ({stop_text}), sampling near the turning "
            f"points (vertex oracle, VNRRT*: {_x(v)} over RRT*) needs {word} sampling "
            f"near the whole path (path oracle, NRRT*: {_x(p)})."
        )
    taut_p = per.get("nrrt_star[oracle_taut_path]")
    taut_v = per.get("vnrrt_star[oracle_taut_vertex]")
    if taut_p and taut_v and "iterations" in taut_p and "iterations" in taut_v:
        out.append(
            f"Read most favourably, with the exact optimum's own segments and turning "
            f"points ({stop_text}): near the path {_x(taut_p['iterations'])}, near "
            f"the turning points {_x(taut_v['iterations'])} fewer iterations than RRT*."
        )
    masked = {
        k: c
        for k, c in per.items()
        if k.startswith("m_vnrrt_star") and k.endswith("[oracle_vertex]") and "iterations" in c
    }
    if masked:
        best = max(masked, key=lambda k: masked[k]["iterations"]["speedup"])
        out.append(
            f"The masked vertex oracle is best at {label(best)}: "
            f"{_x(masked[best]['iterations'])} fewer iterations than RRT* ({stop_text})."
        )
    return out


def regime_section(cells: pd.DataFrame, stop: str) -> str:
    """Speed-up over RRT* per cell (rows) and configuration (columns)."""
    sub = cells[cells["stop"] == stop] if len(cells) else cells
    if sub.empty:
        return "(not run)"
    confs = list(dict.fromkeys(sub["configuration"]))
    lines = [
        "| regime | " + " | ".join(label(c) for c in confs) + " |",
        "|" + " --- |" * (len(confs) + 1),
    ]
    for regime, rows in sub.groupby("regime", sort=False):
        vals = []
        for c in confs:
            r = rows[rows["configuration"] == c]
            vals.append("—" if r.empty else _x(r.iloc[0].to_dict()))
        lines.append(f"| {regime} | " + " | ".join(vals) + " |")
    return "\n".join(lines)


def build_ideas_report(summary: dict, scale: str, figures: list[str]) -> str:
    """The whole ``sampling_ideas.md``; ``figures``: the figure files to show, relative to
    the report."""
    curves = pd.DataFrame(summary["curves"])
    cells = pd.DataFrame(summary["regime"])
    st = summary["settings"]
    eps = st["eps"]
    parts = [
        "# What each sampling idea can give",
        "",
        f"Made at scale `{scale}`: {summary['instances']} random test instances (oracle study), "
        f"{summary['regime_instances']} (regime sweep). Back to "
        "[the paper comparison](paper_comparison.md).",
        "",
        "Oracle heatmaps are built from the labels, not a network "
        "(`vnrrt.evaluation.sources`): the A* path, its interior vertices (the paper's turning "
        "points), the vertices with start and goal, start and goal alone, and the segments and "
        f"turning points of the exact continuous optimum; blurred (Gaussian, sigma "
        f"{st['sigma']:g} px), zero on obstacles, scaled to a maximum of 1. Speed-ups are "
        "paired against RRT* on the same instances: geometric mean of median(RRT*) / "
        f"median(planner), {level_name(st['level'])} CI from {st['bootstrap']:,} bootstrap "
        "resamples over base maps. 'Mass near target' is the share of the heatmap's mass "
        f"within {st['radius']:g} px of its target (the metric the networks report).",
        "",
        "## Conclusion",
        "",
        *[f"- {line}" for line in conclusion(summary)],
        "",
    ]
    for stop in ("initial", "optimal", "optimal_any_angle"):
        if stop in summary["oracle"]:
            parts += [
                f"## Oracles, {stop_name(stop, eps)}",
                "",
                oracle_section(summary["oracle"], stop),
                "",
            ]
    parts += [
        "## The heatmap-quality curve",
        "",
        "Each oracle mixed with a uniform map: signal fraction q of the sampling mass from "
        "the oracle. Speed-up in iterations over RRT* (mass near the target in brackets).",
        "",
    ]
    for stop in ("optimal", "optimal_any_angle"):
        parts += [f"### {stop_name(stop, eps)}", "", curve_table(curves, stop), ""]
    parts += [f"![quality curve]({f})" for f in figures if "quality" in f] + [""]
    parts += [
        "## The planner regime",
        "",
        "Time speed-up over RRT* in the same cell (Steer step eta, near radius, goal "
        f"radius), to within {percent(eps)} of the reference.",
    ]
    for stop in ("optimal", "optimal_any_angle"):
        parts += ["", f"### {stop_name(stop, eps)}", "", regime_section(cells, stop)]
    parts += [""] + [f"![regime]({f})" for f in figures if "regime" in f] + [""]
    return "\n".join(parts) + "\n"
