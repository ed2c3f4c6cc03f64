"""``reports/benchmark_maps.md`` from the study's summary
(:func:`vnrrt.studies.benchmark_maps.summary.analyze`); every number and setting is read from
the summary, which records the run's settings."""

from __future__ import annotations

import math

from vnrrt.names import percent, stop_name
from vnrrt.studies.benchmark_maps.design import STOP
from vnrrt.studies.benchmark_maps.summary import POOLED


def ratio(r: dict) -> str:
    """``1.84x [1.21, 2.90]``; ``n/a`` for NaN, the interval left out where it is NaN."""
    if not math.isfinite(r.get("speedup", math.nan)):
        return "n/a"
    lo, hi = r.get("ci_low", math.nan), r.get("ci_high", math.nan)
    ci = f" [{lo:.2f}, {hi:.2f}]" if math.isfinite(lo) and math.isfinite(hi) else ""
    return f"{r['speedup']:.2f}x{ci}"


def _settings(summary: dict, scale: str) -> list[str]:
    s, maps = summary["settings"], summary["maps"]
    level = f"{100 * s['level']:g}%"
    rows = [
        "| map | size (W x H) | buckets | queries | network inference ms (median) |",
        "| --- | --- | --- | --- | --- |",
    ]
    for name, m in maps.items():
        inf = ", ".join(f"{n} {v:.0f}" for n, v in m["inference_ms"].items()) or "n/a"
        rows.append(
            f"| {name} | {m['width']} x {m['height']} | "
            f"{', '.join(str(b) for b in m['buckets'])} | {m['queries']} | {inf} |"
        )
    return [
        f"Scale `{scale}`. Every configuration plans each query {s['trials']} times with paired "
        f"seeds and stops {stop_name(STOP, s['eps'])} (`vnrrt.search.any_angle_length`), under "
        f"the paper's protocol settings (`conf/planner/default.yaml`): budgets "
        f"{s['max_iterations']:,} iterations and {s['max_seconds']:g} s per run; a run over "
        "either is a failure, entered at the value it stopped at (so a speed-up over a failed "
        "RRT* run is a lower bound). Times are planning only (network inference beside them in "
        f"the table below). Queries: {s['per_bucket']} per length bucket of the MovingAI "
        f"scenario files, drawn with seed {s['seed']}; intervals: {level} paired bootstrap, "
        f"{s['bootstrap']} resamples, clustered by length bucket per map and by map pooled "
        "(`vnrrt.studies.benchmark_maps.summary`).",
        "",
        *rows,
        "",
        "The networks are this scale's, trained on its random floor maps; their heatmaps here "
        "come from each map padded with obstacle rows and columns to the encoder's stride and "
        "cropped back: maps of other sizes and structures than they were trained on (out of "
        "distribution). The envelopes are the oracle families' best "
        "members that the sampling-ideas study chose on random maps for this stop rule: "
        + "; ".join(f"{i} `{k}`" for i, k in summary["envelopes"].items())
        + ".",
    ]


def _cells(summary: dict) -> list[str]:
    names = summary["names"]
    out = [
        "| map | configuration | solved | median ms | median iterations | "
        "speed-up, time | speed-up, iterations | uniform fallbacks |",
        "| --- | --- | --- | --- | --- | --- | --- | --- |",
    ]
    for c in summary["cells"]:
        t, i = (ratio(c[m]) if m in c else "1 (baseline)" for m in ("time_to_stop", "iterations"))
        out.append(
            f"| {c['map']} | {names[c['configuration']]} | {c['solved']}/{c['trials']} "
            f"| {c['median_ms']:.1f} | {c['median_iterations']:,.0f} | {t} | {i} "
            f"| {c['fallbacks']} |"
        )
    return out


def _envelopes(summary: dict) -> list[str]:
    names = summary["names"]
    out = [
        "| map | network configuration | against | time | iterations |",
        "| --- | --- | --- | --- | --- |",
    ]
    for r in summary["against_envelopes"]:
        out.append(
            f"| {r['map']} | {names[r['configuration']]} | {r['idea']} envelope | "
            f"{ratio(r['time_to_stop'])} | {ratio(r['iterations'])} |"
        )
    return out


def _ood(summary: dict) -> list[str]:
    names = summary["names"]
    pooled = {c["configuration"]: c for c in summary["cells"] if c["map"] == POOLED}
    out = [
        "## Out of distribution against in distribution",
        "",
        "The same configurations' speed-ups over RRT* on the random test maps of the paper "
        "comparison (`data/<scale>/summary.json`, stage `evaluate`: random floor maps like the "
        "training maps), beside the pooled real-map ones. The two come from different queries "
        "and are not paired: an interval that does not overlap the other suggests a "
        "difference, overlapping ones do not show there is none.",
        "",
        "| configuration | real maps (pooled), time | random maps, time | "
        "real maps (pooled), iterations | random maps, iterations |",
        "| --- | --- | --- | --- | --- |",
    ]
    for r in summary["in_distribution"]:
        c = pooled[r["configuration"]]
        out.append(
            f"| {names[r['configuration']]} | {ratio(c['time_to_stop'])} | "
            f"{ratio(r['time_to_stop'])} | {ratio(c['iterations'])} | "
            f"{ratio(r['iterations'])} |"
        )
    return out


def _support(summary: dict) -> list[str]:
    eps = summary["settings"]["eps"]
    buckets = ", ".join(f"{n} {len(m['buckets'])}" for n, m in summary["maps"].items())
    return [
        "## What the intervals can support",
        "",
        "Clusters: queries on one map share its structure and are not independent, so the "
        "pooled interval resamples maps (then queries within them): the map is what changes "
        "from one user's workload to the next. Within a map it resamples length buckets (then "
        "queries), so that the interval carries how the speed-up changes with a query's "
        "length, not only the scatter between queries of one length.",
        "",
        summary["caution"] + f" Per map, the interval resamples that map's buckets ({buckets}): "
        "a statement about that map's queries of these lengths, with the same caution where "
        "a map has few buckets. Solve rates are counts within the budgets; where RRT* failed "
        f"to come within {percent(eps)} and a configuration did not, that query's speed-up is "
        "a lower bound.",
    ]


def build_report(summary: dict, scale: str) -> str:
    """The report's markdown (module doc)."""
    lines = [
        "# Benchmark maps: the planners and learned samplers on MovingAI maps",
        "",
        "RRT*, NRRT*, VNRRT* and M-VNRRT* with the trained networks, and the oracle envelopes "
        "(what a perfect heatmap of each idea gives), on the field's standard grid benchmarks "
        "(Sturtevant 2012; `data/movingai/`), "
        f"{stop_name(STOP, summary['settings']['eps'])}. Written by stage "
        "`bench_maps@benchmark_maps`.",
        "",
        "## Setup",
        "",
        *_settings(summary, scale),
        "",
        "## Solve rates and speed-ups over RRT*",
        "",
        "Speed-up: geometric mean over queries of median(RRT*) / median(configuration), "
        "time to the stop rule and iterations (+1); above 1 is faster than RRT*. Uniform "
        "fallbacks: trials whose heatmap had no weight left to sample (M-VNRRT* with no "
        "pixel at or above its threshold), which then sample uniformly, as RRT*.",
        "",
        *_cells(summary),
        "",
        "## Trained networks against their envelopes",
        "",
        "Speed-up of each network's configuration over the envelope of its idea on the same "
        "queries and seeds (below 1: slower than a perfect heatmap of that idea).",
        "",
        *_envelopes(summary),
        "",
        *_ood(summary),
        "",
        *_support(summary),
        "",
    ]
    return "\n".join(lines)


TAG_LIMIT = 8000  # characters MLflow keeps of a tag value (the run's description is a tag)


def description(summary: dict, scale: str) -> str:
    """The study's MLflow run description: the pooled rows of the speed-up table, the
    out-of-distribution table and what the intervals can support (the whole report is the
    run's artifact); under :data:`TAG_LIMIT` characters for any number of maps."""
    pooled = {**summary, "cells": [c for c in summary["cells"] if c["map"] == POOLED]}
    head = (
        f"**The benchmark-maps study at scale `{scale}`** on {', '.join(summary['maps'])}, "
        f"{stop_name(STOP, summary['settings']['eps'])}, pooled over the maps. Per map, the "
        "networks against their envelopes and the setup: the report, `benchmark_maps.html` "
        "under Artifacts."
    )
    return "\n".join([head, "", *_cells(pooled), "", *_ood(summary), "", *_support(summary), ""])
