"""``training_budget.md``: the budget curve's text, from its summary alone
(:mod:`.summary`); every value it names (budgets, eps, tau, CI level, resamples, mass radius,
the paper's training set) comes from the summary's ``settings``."""

from __future__ import annotations

import math

from vnrrt.evaluation.keys import label
from vnrrt.names import level_name, stop_name, stop_title
from vnrrt.studies.training_budget.claims_report import seed_claims_section
from vnrrt.studies.training_budget.reading import fmt_cell, reading
from vnrrt.studies.training_budget.summary import BASELINE

METRIC_NAMES = {"time_to_stop": "Planning time", "iterations": "Iterations"}


def _num(v) -> str:
    return "n/a" if v is None else f"{v:.3g}"


def _table(head: list[str], rows: list[list[str]]) -> list[str]:
    return ["| " + " | ".join(head) + " |", "|" + " --- |" * len(head),
            *["| " + " | ".join(r) + " |" for r in rows], ""]  # fmt: skip


def header(summary: dict) -> list[str]:
    """The title and how to read the report."""
    s, budgets = summary["settings"], summary["budgets"]
    steps = ", ".join(f"{b['steps']:,}" for b in budgets)
    images = ", ".join(f"{b['images']:,}" for b in budgets)
    seeds = summary.get("seeds", [s["train_seed"]])
    pooled = (
        f"pooled over the {len(seeds)} training seeds' networks: the geometric mean over "
        "(seed, instance) of median(RRT*) / median(planner), its bootstrap CI resampling the "
        "training seeds, then base maps, instances and trials (so it includes the training "
        "variance)" if len(seeds) > 1 else "the geometric mean over instances of median(RRT*) "
        "/ median(planner), with a bootstrap CI over base maps, then instances, then trials "
        "(one training seed: no training variance in it)"
    )  # fmt: skip
    return [
        "# The networks over a training budget",
        "",
        f"Made at scale `{s['scale']}` (`conf/scale/{s['scale']}.yaml`), training seeds "
        f"{', '.join(str(v) for v in seeds)} (`budget.seeds`). Both networks trained at each "
        f"budget of {steps} optimizer steps ({images} training images seen) at every seed, "
        "each with a one-cycle learning-rate schedule of its own sized to its steps "
        f"(`conf/budget`), then evaluated on the same {summary['instances']} random test "
        f"instances ({summary['clusters']} base maps) with the protocol's paired seeds; at "
        "the largest budget also on the named maps, for the paper's claims over the seeds.",
        "",
        f"- Speed-ups are paired and {pooled} ({level_name(s['level'])}, {s['bootstrap']} "
        "resamples). Failures (budget hits) enter at their stop value. A ratio X / NRRT* is "
        "median(NRRT*) / median(X): the ratio of the two speed-ups over RRT*, paired.",
        "- A trend is the factor per doubling of the images seen (the slope of the log "
        "speed-up against log2(images)) within one seed's networks, its CI from the same "
        "resampling of base maps and instances, joint over the budgets (they share instances "
        "and seeds): `grows` / `shrinks` where the CI excludes 1, else `no clear trend`; over "
        "several seeds a label holds only where every seed gives it (`differs between seeds` "
        "otherwise), and the factor shown is the geometric mean of the seeds'.",
        "- Heatmap metrics are over the random instances, each in multiples of the same metric "
        "of a uniform map (an AP's: the positives' share; a mass's: the area share).",
        "",
    ]


def training_table(summary: dict) -> list[str]:
    """Per budget and network: epochs, batches per epoch, how far the one-cycle schedule ran
    (its steps taken of its total: a schedule of its own, run to its end), validation."""
    rows = []
    for b in summary["budgets"]:
        for p in b["per_seed"]:
            for name, n in p["networks"].items():
                t, run = n["train"], n["train"].get("budget", {})
                values = [t.get(k) for k in ("val/loss", "val/interior_ap", "val/path_ap")]
                schedule = f"{run.get('schedule_steps')} of {run.get('schedule_total')}"
                rows.append(
                    [f"{b['steps']:,}", f"{b['images']:,}", str(p["seed"]), name,
                     str(run.get("epochs")), str(run.get("batches_per_epoch")), schedule,
                     *[_num(v) for v in values], f"{t.get('fit_seconds', math.nan):.0f}"]
                )  # fmt: skip
    head = ["steps", "images", "seed", "network", "epochs", "batches/epoch",
            "lr schedule steps", "val loss", "val interior AP", "val path AP", "fit s"]  # fmt: skip
    return ["## Training", "", *_table(head, rows)]


HEAT_NAMES = {
    "interior_ap": "interior AP",
    "path_ap": "path AP",
    "mass_near_interior": "mass near interior vertices",
    "mass_near_path": "mass near the path",
    "mass_on_endpoints": "mass on start/goal",
}


def heat_name(key: str) -> str:
    """A heatmap metric's column name: ``mass near interior vertices, τ=0.5 mask``."""
    if key.startswith("mass_near_interior_tau"):
        tau = key.removeprefix("mass_near_interior_tau").replace("_", ".")
        return f"{HEAT_NAMES['mass_near_interior']}, τ={tau} mask"
    return HEAT_NAMES.get(key, key)


def heatmap_table(summary: dict) -> list[str]:
    """Per budget and network: the heatmap metrics in multiples of a uniform map."""
    budgets = summary["budgets"]
    cells = next(iter(budgets[0]["networks"].values()))["heatmap"]
    keys = [k for k, c in cells.items() if "ratio" in c]
    rows = []
    for b in budgets:
        for name, n in b["networks"].items():
            h = n["heatmap"]
            rows.append([f"{b['images']:,}", name, *[_spread(h[k], "ratio") for k in keys],
                         _spread(h["interior_recall"], "value")])  # fmt: skip
    h = summary["settings"]["heatmap"]
    head = ["images", "network", *[heat_name(k) for k in keys], "interior recall"]
    return [
        "## The heatmaps, in multiples of a uniform map",
        "",
        f"Mass within {h['radius']:g} px (start/goal disks: {h['endpoint_radius']:g} px); AP "
        f"against targets dilated by {h['ap_radius']:g} px, the interior AP with the start/goal "
        "disks left out; a τ mask: the interior mass after M-VNRRT*'s mask (probabilities "
        f"below τ set to zero); interior recall at probability {h['tau']:g} (as measured, not a "
        "multiple). Over several training seeds: the mean over the seeds' networks "
        "[smallest, largest].",
        "",
        *_table(head, rows),
    ]


def _spread(cell: dict, field: str) -> str:
    """A heatmap metric: ``1.23`` (one seed) or ``1.23 [1.10, 1.40]`` (mean [min, max])."""
    if "low" not in cell:
        return _num(cell[field])
    return f"{_num(cell[field])} [{_num(cell['low'])}, {_num(cell['high'])}]"


def _hits(b: dict, stop: str, metric: str, keys: list[str]) -> str:
    """Budget hits (failed trials) of each configuration, in ``keys`` order: ``0/1/0/2``."""
    over = b["speedups"][stop][metric]
    base = next(iter(over.values()))["failed_baseline"]
    return "/".join(str(v) for v in [base, *[over[k]["failed_planner"] for k in keys[1:]]])


def speedup_tables(summary: dict) -> list[str]:
    """Per stop rule and metric: the speed-ups over RRT* and the ratios to NRRT*, and the
    budget hits (failed trials, entered at their stop value) of each configuration."""
    s, out = summary["settings"], []
    keys, ratios = s["keys"], s["ratio_keys"]
    names = "/".join(label(k) for k in keys)
    for stop in s["stops"]:
        title = stop_title(stop, s["eps"])
        out += [f"## {title[0].upper()}{title[1:]}", ""]
        for metric in summary["metrics"]:
            head = ["images", *[f"{label(k)} over RRT*" for k in keys[1:]],
                    *[f"{label(k)} / NRRT*" for k in ratios], f"budget hits ({names})"]  # fmt: skip
            rows = [[f"{b['images']:,}",
                     *[fmt_cell(b["speedups"][stop][metric][k]) for k in keys[1:]],
                     *[fmt_cell(b["ratios"][stop][metric][k]) for k in ratios],
                     _hits(b, stop, metric, keys)]
                    for b in summary["budgets"]]  # fmt: skip
            out += [f"{METRIC_NAMES[metric]}:", "", *_table(head, rows)]
    return out


def trend_table(summary: dict) -> list[str]:
    """Every trend: per doubling of the images seen, with its CI and verdict."""
    s = summary["settings"]
    rows = [[f"{label(t['planner'])} {'over' if t['base'] == BASELINE else '/'} "
             f"{label(t['base'])}", stop_name(t["stop"], s["eps"]), METRIC_NAMES[t["metric"]],
             fmt_cell({"speedup": t["per_doubling"], "ci_low": t["ci_low"],
                       "ci_high": t["ci_high"]}), _seed_trends(t), t["verdict"]]
            for t in summary["trends"]]  # fmt: skip
    head = ["speed-up or ratio", "stop rule", "metric", "per doubling [CI]",
            "per seed: per doubling [CI] (trend)", "trend"]  # fmt: skip
    return ["## Trends over the images seen (factor per doubling)", "", *_table(head, rows)]


def _seed_trends(t: dict) -> str:
    """Each seed's trend: ``0: 1.05 [0.9, 1.2] (no clear trend); 1: ...``."""
    parts = []
    for seed, v in (t.get("per_seed") or {}).items():
        cell = {"speedup": v["per_doubling"], "ci_low": v["ci_low"], "ci_high": v["ci_high"]}
        parts.append(f"{seed}: {fmt_cell(cell)} ({v['verdict']})")
    return "; ".join(parts) or "n/a"


def build_budget_report(summary: dict, figures: list[str]) -> str:
    """The whole report; ``figures``: the figure files relative to the report."""
    lines = header(summary) + reading(summary) + seed_claims_section(summary)
    lines += training_table(summary) + heatmap_table(summary)
    lines += speedup_tables(summary) + trend_table(summary)
    lines += ["## Figures", "", *[f"![{f}]({f})" for f in figures], ""]
    return "\n".join(lines)
