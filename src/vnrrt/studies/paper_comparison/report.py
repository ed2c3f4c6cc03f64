"""``paper_comparison.md``: the paper's Tables 1-3 beside ours, its quoted claims with our
verdicts, and how to read both. A renderer only: every number comes from the summary of
:func:`vnrrt.studies.paper_comparison.summary.analyze` (with the settings it was computed
with: tolerance, CI level, resamples), the networks' metrics with the settings of
``predict``, and the paper's numbers from ``data/paper/tables.yaml`` (data, never typed in
here).

Cells are plain text on one line (no HTML), so the file reads the same on GitHub, in a
terminal and in MLflow's artifact viewer.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from vnrrt.evaluation.keys import is_informed, label, sort_texts
from vnrrt.names import MAP_SET_NAMES as COLUMN_NAMES
from vnrrt.names import level_name, percent, stop_title
from vnrrt.studies.paper_comparison.claims import CONTRADICTS, verdict_text
from vnrrt.studies.paper_comparison.claims import improvement as _imp
from vnrrt.studies.paper_comparison.claims_report import (
    difference_table,
    estimand_table,
    strata_section,
)
from vnrrt.studies.paper_comparison.disclosure import (
    mask_section,
    networks_scale_table,
    settings_table,
)
from vnrrt.studies.paper_comparison.headline import VERDICT_GROUPS
from vnrrt.studies.paper_comparison.networks_report import (
    MetricSettings,
    inference_table,
    networks_section,
)
from vnrrt.studies.paper_comparison.networks_report import num as _num
from vnrrt.studies.paper_comparison.timing import timing_section


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


def claims_table(claims: dict) -> str:
    """The paper's quoted claims: the paper's value and its interval from its own data, ours
    read on time (the verdict), on time with the network's inference, and on iterations, the
    compatibility with the paper's data and whether a masked claim tests its mask."""
    head = (
        "| claim | paper | paper's interval (its data) | ours: time, gm ratio of medians "
        "[CI] | ours: ratio of means [CI] | ours: planning + inference [CI] | ours: iterations "
        "[CI] | verdict | the paper's data | tests the mask? |"
    )
    lines = [head, "|" + " --- |" * 10]
    for r in claims["rows"]:
        p = r["paper"]
        paper_iv = f"[{p['low']:+.1%}, {p['high']:+.1%}]" + ("" if p["significant"] else " (n.s.)")
        t, it, total = r["time_to_stop"], r["iterations"], r.get("time_total")
        if t is None:
            cells = ["no data"] * 4 + ["no data", "—"]
        else:
            cells = [_imp(t), _imp(t, "rom_ci_low", "rom_ci_high", "ratio_of_means"),
                     _imp(total) if total else "—", _imp(it), verdict_text(r),
                     r["paper_data"]]  # fmt: skip
        tm = r["testability"]
        cells.append(
            "yes" if tm["testable"] else f"no: not testable with this network ({tm['why']})"
        )
        lines.append(
            f"| {r['text']} | {r['quoted']:+.2%} | {paper_iv} | " + " | ".join(cells) + " |"
        )
    return "\n".join(lines)


def masked_claims_section(summary: dict) -> list[str]:
    """What each masked claim tests: where the heatmap samplers put their mass after the
    mask, and the rule that marks a claim untestable."""
    table = mask_section(summary)
    if not table:
        return []
    rule = summary["claims"]["testability_rule"]
    return [
        "### What the masked claims test",
        "",
        "Where each heatmap sampler's weights lie (after M-VNRRT*'s mask), averaged over the "
        "random instances, to within "
        f"{percent(summary['eps'])} of A*, and how often the sampler falls back to uniform "
        "sampling (nothing above tau). The M-VNRRT* variants apply the mask to the "
        "max-normalised heatmap (as for the oracles) or leave out the start/goal disks; the "
        "masked NRRT* control is M-VNRRT*'s sampler on the path network's heatmap, so the "
        "mask's effect is separated from the target's.",
        "",
        *table,
        "",
        f"A masked claim is 'not testable with this network' when {rule}.",
        "",
    ]


def multiple_note(claims: dict) -> str:
    """How the claims were tested: the corrected level, the resamples and their tail count,
    and which claims are significant in the paper's own data."""
    rows = [r for r in claims["rows"] if r["time_to_stop"]]
    testable = [r for r in rows if r["testability"]["testable"]]
    contra = sum(r["paper_data"] == CONTRADICTS for r in testable)
    slow = sum(r["quoted"] < 0 for r in claims["rows"])
    sig = [r["text"] for r in claims["rows"] if r["paper"]["significant"]]
    return (
        f"{len(claims['rows'])} quoted claims ({len(claims['rows']) - slow} improvements, "
        f"{slow} slow-downs), {claims['claims']} with data here. One verdict per claim, on "
        "time (its metric); iterations and planning + inference are second readings. Every "
        f"interval of this table is at {claims['corrected_level']:.3%} (Bonferroni over the "
        f"{claims['claims']} claims: family-wise {level_name(claims['level'])}), ours from "
        f"{claims['bootstrap']:,} bootstrap resamples ({claims['tail_draws']:.0f} in each tail). "
        "The paper's interval comes from its own means, standard deviations and trial counts "
        "(the delta method on the log of a ratio of independent means: it assumes its planners "
        "unpaired, as its tables report them; its sensitivity to pairing is below); '(n.s.)' "
        "marks a claim whose interval contains zero, not significant in the paper's own data. "
        "Our ratio of means (the paper's estimand) is 'compatible with the paper's data' when "
        "the interval of the difference between ours and the paper's contains no difference, "
        "and 'contradicts' it when it does not. "
        f"Significant in the paper's own data: {len(sig)} of {len(claims['rows'])}"
        + (f" ({'; '.join(sig)})." if sig else ".")
        + f" Verdicts of the {len(testable)} testable claims: "
        f"{_counts([r['verdict'] for r in testable])}; {len(rows) - len(testable)} untestable "
        f"(no verdict counted); {contra} testable claims contradict the paper's data."
    )


def _counts(verdicts: list[str]) -> str:
    groups = {g: sum(v.startswith(g) for v in verdicts) for g in VERDICT_GROUPS}
    return ", ".join(f"{n} {g}" for g, n in groups.items())


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


def rules(level: float, bootstrap: int) -> str:
    """How to read the tables (CIs at ``level`` from ``bootstrap`` resamples)."""
    return RULES.format(level=level_name(level), bootstrap=f"{bootstrap:,}")


RULES = """How to read the tables:
- Our cells: median (mean±std) successful/trials, planning time in ms (the paper's in s).
  Times are planning only: the sampler is built from the heatmap once per (instance,
  configuration), outside the timed region (median build time below), and the network's
  inference is per map (its own table).
- Failures (budget hits) are not dropped: they enter times and iterations at the value at
  which the budget stopped them, a lower bound; a mean with failures is shown as ">=", a
  median as ">=" unless fewer than half the trials failed (and none below it). Path lengths
  are over successful trials. "fallback k": k trials whose masked heatmap had nothing above
  tau, so M-VNRRT* sampled uniformly (it was RRT* then).
- Comparisons are paired: every configuration runs on the same instances with the same trial
  seeds. A speed-up is the geometric mean over instances of median(baseline) /
  median(planner); its {level} CI ({bootstrap} bootstrap resamples) resamples base maps
  (instances of one map are not independent), then instances, then trials within each
  instance. The paper's ratio of means is shown beside it.
- Verdicts (one per claim, on time; at the claims' corrected level): "reproduced" = same sign
  and the paper's value inside our CI; "same direction, smaller/larger effect" = the CI
  excludes zero on the paper's side, not the paper's value, and the interval of the
  difference between ours and the paper's (both noises) excludes no difference; "same
  direction, size within the paper's noise" = as before but the difference interval contains
  no difference; "no clear effect" = the CI contains zero; "reversed" = the CI excludes zero
  on the other side. Beside it, by the interval of the difference between our ratio of means
  and the paper's: "compatible with the paper's data" or "contradicts the paper's data".
- Our named maps are our own (built to the paper's difficulty ordering, not to its
  geometry, which the paper does not give), so claims on Maps 1-5 are marked "different map:
  not comparable"; the random-maps column is the comparable one."""


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


@dataclass(frozen=True)
class ReportInputs:
    """Everything ``paper_comparison.md`` shows: the statistics (``summary``, with the
    settings they were computed with), the paper's numbers and settings (``paper``,
    ``settings``: ``tables.yaml`` and ``settings.yaml``), the instances' optimal lengths, each
    configuration's network (``sources``), the networks' heatmap metrics (``networks``,
    ``predict.json``, computed with ``metric_settings``) and training records
    (``trainings``), the run's value of every setting the settings table names
    (``values``), and in an ablation its claims against the default run's (``changes``,
    :func:`vnrrt.evaluation.noise.changes`; ``overrides``: what the ablation changed)."""

    summary: dict
    paper: dict
    optima: dict
    sources: dict[str, str]
    scale: str
    networks: dict[str, dict]
    metric_settings: MetricSettings
    settings: dict
    values: dict
    trainings: dict[str, dict]
    changes: list[dict] | None = None
    overrides: str = ""


def build_report(inp: ReportInputs) -> str:
    """The whole ``paper_comparison.md`` text (:class:`ReportInputs`)."""
    summary, paper, optima = inp.summary, inp.paper, inp.optima
    cols = paper["columns"]
    eps = summary["eps"]
    parts = [
        "# VertexNet RRT*: the paper's tables beside this reproduction",
        "",
        f"Made at scale `{inp.scale}` (`conf/scale/{inp.scale}.yaml`); eps = {eps:g}. What a "
        "perfect network would give each sampling idea, and in which planner regime: "
        "[sampling_ideas.md](sampling_ideas.md).",
        "",
        rules(summary["level"], summary["bootstrap"]),
        "",
        "## The paper's quoted claims",
        "",
        claims_table(summary["claims"]),
        "",
        multiple_note(summary["claims"]),
        "",
        "These claims read one trained network pair (the pipeline's `train.seed`): their "
        "intervals hold no training variance. The random-map claims read over several "
        "training seeds' network pairs, with intervals that include it, are in "
        "[training_budget.md](training_budget.md) at the scales that train them "
        "(`budget.seeds`).",
        "",
        "### Each claim under both estimands",
        "",
        "The paper's estimand (ratio of means) and ours (geometric mean of per-instance ratios "
        "of medians), each on planning time and on iterations, at the claims' corrected level; "
        "the verdict is the first reading's, and the robustness column says whether every "
        "other reading gives the same category, or which moves it.",
        "",
        estimand_table(summary["claims"]),
        "",
        "### Against the paper's own data: the interval of the difference",
        "",
        "Our ratio of means and the paper's, compared by the interval of their ratio (ours / "
        "paper: a difference on the log scale, the two standard errors combined as "
        "independent samples). The paper's interval assumes its planners unpaired; had they "
        "run on the same maps with correlated times, its interval would be narrower "
        "(correlation columns; `stats.pairing`).",
        "",
        difference_table(summary["claims"]),
        "",
        *strata_section(summary, cols, COLUMN_NAMES),
        *masked_claims_section(summary),
        *timing_section(summary, inp.changes, inp.overrides),
        "## Settings: this run beside the paper",
        "",
        settings_table(inp.settings, inp.values),
        "",
        "The stop rule 'optimal' is our reading of a paragraph the paper's source comments out; "
        f"'within {percent(eps)} of the exact continuous optimum' (below) is the more "
        "comparable rule. The networks of this run:",
        "",
        networks_scale_table(inp.trainings, inp.scale, inp.settings["paper_network"]),
        "",
        "## Optimal path lengths (px)",
        "",
        optima_table(paper, optima),
        "",
        "The paper's 'optimal' is its A* length. Ours is A* on the 8-connected grid without "
        "corner cutting, between cell centres; the exact continuous optimum (shortest path "
        f"among closed obstacle cells, through convex obstacle corners) is {shorter_range(optima)} "
        f"shorter, so '{percent(eps)} of A*' is a loose target for a continuous planner.",
        "",
    ]
    for spec in paper["tables"].values():
        unit = 1e3 if spec["metric"] == "time_to_stop" else 1.0
        suffix = " (paper: s; ours: ms)" if unit != 1.0 else ""
        parts += [
            f"## {spec['title']}{suffix}",
            "",
            table(summary, spec, cols, spec["metric"], unit),
            "",
        ]
    if "optimal_any_angle" in summary["stops"]:
        spec = {"stop": "optimal_any_angle"}
        parts += [
            f"## Time to within {percent(eps)} of the exact continuous optimum (ms; ours, not "
            "in the paper)",
            "",
            table(summary, spec, cols, "time_to_stop", 1e3),
            "",
        ]
    for stop in summary["stops"]:
        parts += [
            f"## Iterations, {stop_title(stop, eps)} (ours; not in the paper)",
            "",
            table(summary, {"stop": stop}, cols, "iterations"),
            "",
        ]
    for stop in summary["stops"]:
        parts += [
            f"## Paired speed-up over RRT*, time, {stop_title(stop, eps)}",
            "",
            "Planning only:",
            "",
            speedup_table(summary["over_rrt_star"]["time_to_stop"], stop, cols),
            "",
            "Planning + the network's inference per map:",
            "",
            speedup_table(summary["over_rrt_star"]["time_total"], stop, cols),
            "",
        ]
    if summary.get("informed"):
        parts += [
            "## Informed sampling: does the learned sampler help on top of it? (ours, not "
            "in the paper)",
            "",
            "Every configuration again with informed sampling (Gammell et al. 2014: once a "
            "solution exists, samples inside the ellipse of shorter paths; nodes that cannot "
            "improve it skipped), on the random instances; paired speed-ups with "
            f"{level_name(summary['level'])} CIs.",
            "",
            informed_section(summary),
        ]
    setup = ", ".join(f"{label(k)} {v:.2f} ms" for k, v in summary["setup_ms"].items())
    parts += networks_section(inp.networks, inp.metric_settings)
    parts += [
        "## Planning time and network inference",
        "",
        inference_table(summary, summary["inference_ms"], inp.sources),
        "",
        "The paper does not say whether its times include the network's inference; its "
        "Algorithm 2 runs the network as its first line. Read the paper's NRRT*/VNRRT*/M-VNRRT* "
        "times against our 'planning + inference' column if they include it, against "
        "'planning' if not; RRT* runs no network, so its times compare directly either way.",
        "",
        f"Median sampler build time per (instance, configuration), not in the planning "
        f"times: {setup}.",
        "",
    ]
    return "\n".join(parts) + "\n"
