"""``reports/sampling_ideas.md``: what each sampling idea can give (oracle families, their
envelopes chosen on selection instances and reported on evaluation instances, the
path-vertex blend, the heatmap-quality curve, the obstacle rule, the planner regime) and a
conclusion computed from the numbers. A renderer of
:func:`vnrrt.studies.sampling_ideas.summary.analyze_study`'s summary; every setting it names
(tolerance, CI level, mass radius, the obstacle rule) comes from the summary's ``settings``."""

from __future__ import annotations

import math

from vnrrt.evaluation.keys import ConfigKey, label
from vnrrt.names import level_name, percent, stop_name
from vnrrt.studies.sampling_ideas.design import PROTOCOL
from vnrrt.studies.sampling_ideas.findings import (
    OPTIMAL_STOPS,
    OWN_TEXT,
    VERTEX_IDEAS,
    cell_row,
    conclusion,
    ideas_of,
    pct,
    speedup_text,
)
from vnrrt.studies.sampling_ideas.per_cell import own_table
from vnrrt.studies.sampling_ideas.summary import sweep_columns


def censored_cells(summary: dict, stop: str) -> list[tuple[str, float, float, str, int, int]]:
    """``(cell, RRT*'s share, the lowest share, its configuration, runs stopped by the time
    budget, runs cut at their wall-clock cap)`` for every regime cell where some runs did not
    reach ``stop`` within the planner's budget, in the study's order (a summary written before
    the cap counted its runs cut by time as cut at the cap: the budget was the cap)."""
    out = []
    for cell in summary["cell_names"]:
        rows = [r for r in summary["cells"] if r["regime"] == cell and r["stop"] == stop]
        low = min(rows, key=lambda r: r["success_rate"], default=None)
        if low is None or low["success_rate"] >= 1.0:
            continue
        base = next((r for r in rows if r["configuration"] == "rrt_star"), None)
        rrt = base["success_rate"] if base else math.nan
        cut = sum(r.get("cut_by_time", 0) for r in rows)
        cap = sum(r.get("cut_by_cap", r.get("cut_by_time", 0)) for r in rows)
        out.append((cell, rrt, low["success_rate"], low["configuration"], cut, cap))
    return out


def budget_table(summary: dict, stop: str) -> str:
    """The cells with runs stopped by the budget (:func:`censored_cells`), and how many of
    their runs the time budget stopped (their iterations depend on the machine)."""
    rows = censored_cells(summary, stop)
    if not rows:
        return "Every run of every cell reached the stop rule within the budget."
    cut, cap = sum(r[4] for r in rows), sum(r[5] for r in rows)
    factor = float(summary.get("settings", {}).get("cap_factor", 1.0))
    lines = [
        "Runs that reached the stop rule within the budget, where some did not (the others "
        "enter the statistics at the budget, censored: RRT*'s censored runs make a speed-up a "
        "lower bound, the planner's an upper bound). The time budget (`planner.max_seconds`) "
        f"is applied after each run, whose own wall-clock cap is {factor:g} times it "
        "(`eval.cap_factor`): a run over the budget counts as stopped there in the time "
        f"readings ({cut} run{'s' if cut != 1 else ''} over every configuration of these "
        "cells), while the iteration "
        "readings see it stopped by the iteration budget only, unless it reached the cap: such "
        "a run stops at an iteration count that depends on the machine's speed "
        f"(the last column, {cap} in all"
        + (")." if cap else "; no iteration reading here depends on the machine's speed)."),
        "",
        "| cell | RRT* | lowest | its configuration | runs stopped by the time budget | runs "
        "cut at the cap |",
        "| --- | --- | --- | --- | --- | --- |",
    ]
    lines += [f"| {c} | {pct(r)} | {pct(lo)} | {label(k)} | {n} | {m} |"
              for c, r, lo, k, n, m in rows]  # fmt: skip
    return "\n".join(lines)


def selection_table(summary: dict, stop: str) -> str:
    """Per family: members tried, the envelope chosen, its selection speed-up and whether it
    sits on its grid's edge (:mod:`.edges`)."""
    sel = summary["selection"]
    lines = [
        "| family | members | envelope (chosen) | its speed-up on the selection | on its grid's "
        "edge? |",
        "| --- | --- | --- | --- | --- |",
    ]
    for idea, cells in sel["speedups"].get(stop, {}).items():
        chosen = sel["envelopes"].get(stop, {}).get(idea)
        if chosen:
            e = sel.get("edges", {}).get(stop, {}).get(idea)
            where = "—" if e is None else _edge_cell(e)
            lines.append(
                f"| {idea} | {len(cells)} | {label(chosen)} | {cells[chosen]:.2f}x | {where} |"
            )
    return "\n".join(lines)


def _edge_cell(edges: list[str]) -> str:
    """An envelope's place on its grid: its edges, or interior (a bound)."""
    return "; ".join(edges) + ": the best measured member" if edges else "no: interior, a bound"


def envelope_table(summary: dict, stop: str) -> str:
    """Per regime cell: each envelope's iteration speed-up over RRT* and the turning-point
    and blend envelopes against the path envelope."""
    env = summary["selection"]["envelopes"].get(stop, {})
    vs = {
        (r["regime"], r["idea"]): r["iterations"] for r in summary["envelopes"] if r["stop"] == stop
    }
    ideas = ideas_of(summary)
    against = [i for i in ideas if i in VERTEX_IDEAS or i == "blend"]
    head = "| cell | " + " | ".join([*ideas, *(f"{i} / path" for i in against)]) + " |"
    lines = [head, "|" + " --- |" * (len(ideas) + len(against) + 1)]
    for cell in summary["cell_names"]:
        got = [
            speedup_text((cell_row(summary, cell, stop, env.get(i)) or {}).get("iterations"))
            for i in ideas
        ]
        if all(g == "—" for g in got):
            continue
        got += [speedup_text(vs.get((cell, i))) for i in against]
        lines.append(f"| {cell} | " + " | ".join(got) + " |")
    return "\n".join(lines)


def blend_table(summary: dict, stop: str) -> str:
    """Per cell: the blend at each w > 0 against w = 0 (fewer iterations: above 1)."""
    rows = [b for b in summary["blend"] if b["stop"] == stop]
    weights = sorted({b["w"] for b in rows})
    if not weights:
        return "(not run)"
    lines = [
        "| cell | " + " | ".join(f"w = {w:g}" for w in weights) + " |",
        "|" + " --- |" * (len(weights) + 1),
    ]
    for cell in summary["cell_names"]:
        got = {b["w"]: b["iterations"] for b in rows if b["regime"] == cell}
        if got:
            lines.append(
                f"| {cell} | " + " | ".join(speedup_text(got.get(w)) for w in weights) + " |"
            )
    return "\n".join(lines)


def quality_table(summary: dict, stop: str) -> str:
    """The quality curve: per idea, envelope diluted (every stop rule's, ``*`` marking this
    stop rule's own) and q, the heatmap's mass near the target (x uniform) and the iteration
    speed-up over RRT*."""
    rows = [r for r in summary["curves"] if r["stop"] == stop and r["metric"] == "iterations"]
    if not rows:
        return "(not run)"
    lines = [
        "| idea | envelope diluted | q | mass near target | x a uniform map's | "
        "speed-up, iterations |",
        "| --- | --- | --- | --- | --- | --- |",
    ]
    for r in sorted(rows, key=lambda r: (r["idea"], not r["own"], r["member"], -r["q"])):
        x = "—" if r["x_uniform"] is None else f"{r['x_uniform']:.1f}x"
        name = label(r["member"]) + (" *" if r["own"] else "")
        mass = pct(r["heat_mass"])
        lines.append(f"| {r['idea']} | {name} | {r['q']:g} | {mass} | {x} | {speedup_text(r)} |")
    return "\n".join(lines)


def rule_table(summary: dict, stop: str) -> str:
    """The protocol cell's configurations under both obstacle rules (speed-up over RRT* under
    the same rule, iterations)."""
    rows = [
        r
        for r in summary["cells"]
        if r["regime"] == PROTOCOL
        and r["stop"] == stop
        and "iterations" in r
        and "@q" not in r["configuration"]
    ]
    by = {}
    for r in rows:
        key = ConfigKey.parse(r["configuration"])
        by.setdefault(key.with_free(False).text, {})[key.free] = r["iterations"]
    pairs = {k: v for k, v in by.items() if len(v) == 2}
    if not pairs:
        return "(not run)"
    lines = ["| configuration | every cell | free cells only |", "| --- | --- | --- |"]
    lines += [
        f"| {label(k)} | {speedup_text(v[False])} | {speedup_text(v[True])} |"
        for k, v in pairs.items()
    ]
    return "\n".join(lines)


def regime_section(summary: dict, stop: str) -> str:
    """Time speed-up over RRT* per cell (rows) and configuration run in every cell
    (columns, :func:`.summary.sweep_columns`)."""
    rows = [r for r in summary["regime"] if r["stop"] == stop]
    if not rows:
        return "(not run)"
    confs = sweep_columns(rows)
    lines = [
        "| cell | " + " | ".join(label(c) for c in confs) + " |",
        "|" + " --- |" * (len(confs) + 1),
    ]
    for cell in dict.fromkeys(r["regime"] for r in rows):
        got = {r["configuration"]: r for r in rows if r["regime"] == cell}
        lines.append(f"| {cell} | " + " | ".join(speedup_text(got.get(c)) for c in confs) + " |")
    return "\n".join(lines)


def _intro(summary: dict, scale: str) -> list[str]:
    st = summary["settings"]
    rule = "free cells only" if st["zero_obstacles"] else "every cell, obstacles included"
    return [
        f"Made at scale `{scale}`. Oracle heatmaps are built from the labels, not a network "
        "(`vnrrt.evaluation.oracles`): each idea is a family of oracles over its targets, "
        "blurs (Gaussian sigma) and heatmap-draw probabilities, and the path-vertex blend H_w "
        "spans the space between the two ideas. Each family's best member (its envelope) is "
        f"chosen on {summary['selection']['instances']} selection instances of "
        f"{len(summary['selection']['maps'])} base maps ({st['selection_share']:.0%} of the maps) "
        f"and reported on {summary['instances']} evaluation instances of "
        f"{len(summary['maps'])} other base maps. Speed-ups are paired against RRT* in the same "
        "cell and under the same obstacle rule: geometric mean of median(RRT*) / "
        f"median(planner), {level_name(st['level'])} CI from {st['bootstrap']:,} bootstrap "
        "resamples over base maps. 'Mass near target' is the share of the heatmap's mass "
        f"within {st['radius']:g} px of its target. The obstacle rule, one for every heatmap "
        f"source and for the uniform part of every sampler: {rule} (the default; "
        "`eval.zero_obstacles`: the paper's uniform sampling covers the whole map and its "
        "networks' heatmaps are used as predicted); the other rule is measured once, in the "
        "protocol's cell. Back to [the paper comparison](paper_comparison.md).",
    ]


def build_ideas_report(summary: dict, scale: str, figures: list[str]) -> str:
    """The whole ``sampling_ideas.md``; ``figures``: the figure files to show, relative to
    the report."""
    eps = summary["settings"]["eps"]
    parts = [
        "# What each sampling idea can give",
        "",
        *_intro(summary, scale),
        "",
        "## Conclusion",
        "",
        *[f"- {line}" for line in conclusion(summary)],
        "",
    ]
    for stop in ("initial", *OPTIMAL_STOPS):
        if stop not in summary["selection"]["speedups"]:
            continue
        parts += [
            f"## Envelopes, {stop_name(stop, eps)}",
            "",
            "Selection:",
            "",
            selection_table(summary, stop),
            "",
            "Evaluation (fewer iterations than RRT*, and the turning-point and blend "
            "envelopes against the path envelope):",
            "",
            envelope_table(summary, stop),
            "",
            "The blend at each w against w = 0:",
            "",
            blend_table(summary, stop),
            "",
        ]
    if summary.get("own"):
        parts += ["## Envelopes selected in each regime cell", "", OWN_TEXT, ""]
        for stop in OPTIMAL_STOPS:
            parts += [f"### {stop_name(stop, eps)}", "", own_table(summary["own"], stop), ""]
    parts += [
        "## The heatmap-quality curve",
        "",
        "Each path and vertex envelope diluted "
        "towards a uniform map (signal fraction q), in the protocol's cell; every stop rule's "
        "envelopes are run under each stop rule, * marks the stop rule's own (the figure shows "
        "only those, and the conclusion reads only those).",
        "",
    ]
    for stop in OPTIMAL_STOPS:
        parts += [f"### {stop_name(stop, eps)}", "", quality_table(summary, stop), ""]
    parts += [f"![quality curve]({f})" for f in figures if "quality" in f] + [""]
    parts += ["## The obstacle rule", "", rule_table(summary, "optimal"), ""]
    parts += [
        "## The planner regime",
        "",
        "Time speed-up over RRT* in the same cell (Steer "
        f"step eta, near-radius rule, goal radius), to within {percent(eps)} of the reference.",
    ]
    for stop in OPTIMAL_STOPS:
        parts += ["", f"### {stop_name(stop, eps)}", "", regime_section(summary, stop)]
        parts += ["", budget_table(summary, stop)]
    parts += [""] + [f"![regime]({f})" for f in figures if "regime" in f] + [""]
    return "\n".join(parts) + "\n"
