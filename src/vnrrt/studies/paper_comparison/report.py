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

from dataclasses import dataclass

from vnrrt.evaluation.keys import label
from vnrrt.names import MAP_SET_NAMES as COLUMN_NAMES
from vnrrt.names import level_name, percent, stop_title
from vnrrt.studies.paper_comparison.claims_report import (
    claims_table,
    difference_table,
    estimand_table,
    masked_claims_section,
    multiple_note,
    strata_section,
)
from vnrrt.studies.paper_comparison.disclosure import networks_scale_table, settings_table
from vnrrt.studies.paper_comparison.networks_report import (
    MetricSettings,
    inference_table,
    networks_section,
)
from vnrrt.studies.paper_comparison.tables import (
    informed_section,
    optima_table,
    shorter_range,
    speedup_table,
    table,
)
from vnrrt.studies.paper_comparison.timing import timing_section


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
        "intervals hold no training variance. The claims read over several training seeds' "
        "network pairs, with intervals that include it, are in "
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
    parts += _metric_tables(summary, paper)
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


def _metric_tables(summary: dict, paper: dict) -> list[str]:
    """The paper's tables beside ours, then ours alone: time to the exact optimum,
    iterations per stop rule and the paired speed-ups over RRT*."""
    cols, eps, parts = paper["columns"], summary["eps"], []
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
    return parts
