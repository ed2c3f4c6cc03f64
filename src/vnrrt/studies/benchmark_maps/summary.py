"""The benchmark-maps study's statistics, from its trial table (:mod:`vnrrt.evaluation.stats`
rules: failures censored at the value they stopped at, paired comparisons on the same queries
and trial seeds, bootstrap intervals).

**Clusters.** Per map, a query's cluster is its length bucket: the buckets are resampled,
then queries within each, so the interval carries how the speed-up changes with the query's
length, not only the scatter between queries of one length. Pooled over maps, the cluster is
the map: queries on one map share its structure and are not independent, and the map is the
unit a new user's workload changes. With few maps the pooled interval describes these maps
only (:func:`pooled_caution`).

Summary (JSON-ready): ``settings`` (what the readers print), ``maps`` (name -> size, queries,
buckets, inference ms), ``cells`` (one row per map or ``pooled`` and configuration: solve
rate, medians, speed-ups over RRT* in time and iterations with CIs), ``envelopes`` (each
trained network against its family's envelope), ``in_distribution`` (the same networks'
speed-ups on the random test maps, from the paper comparison's summary).
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd

from vnrrt.evaluation.keys import ConfigKey
from vnrrt.evaluation.stats import compare
from vnrrt.studies.benchmark_maps.design import NETWORK_IDEA, STOP

POOLED = "pooled"
BASELINE = "rrt_star"
METRICS = ("time_to_stop", "iterations")
READ = ("speedup", "ci_low", "ci_high")
FEW_CLUSTERS = 10  # below this many maps a cluster bootstrap's interval is known to be too narrow


def config_names(keys: list[str], envelopes: dict[str, str]) -> dict[str, str]:
    """``{key text: name}``: a display name per configuration, ``<idea> envelope`` for an
    envelope (``envelopes``: idea -> key text), the key's label otherwise."""
    by_key = {text: f"{idea} envelope" for idea, text in envelopes.items()}
    return {k: by_key.get(k, ConfigKey.parse(k).label) for k in keys}


def _clustered(table: pd.DataFrame, group: str) -> pd.DataFrame:
    """``table`` with ``cluster`` codes of the map (``pooled``) or of the bucket (per map)."""
    if group != POOLED:
        return table
    codes = {m: i for i, m in enumerate(dict.fromkeys(table["map_set"]))}
    return table.assign(cluster=table["map_set"].map(codes).astype(np.int64))


def _speedup(base: pd.DataFrame, plan: pd.DataFrame, metric: str, stats: dict) -> dict:
    c = compare(
        base, plan, metric, n_boot=stats["bootstrap"], level=stats["level"], seed=stats["seed"]
    )
    return {
        "speedup": c.speedup,
        "ci_low": c.ci_low,
        "ci_high": c.ci_high,
        "clusters": c.clusters,
        "instances": c.instances,
    }


def cell(sub: pd.DataFrame, base: pd.DataFrame, key: str, stats: dict) -> dict:
    """One configuration's row on one map (or pooled): trials, solved, solve rate, trials
    whose heatmap sampler fell back to uniform sampling (M-VNRRT* with nothing above tau),
    median planning ms and iterations (failures at their budget), speed-ups over RRT*."""
    out = {
        "trials": int(len(sub)),
        "solved": int(sub["success"].sum()),
        "solve_rate": float(sub["success"].mean()),
        "fallbacks": int(sub["fallback_uniform"].sum()),
        "median_ms": float(np.median(sub["time_to_stop"]) * 1e3),
        "median_iterations": float(np.median(sub["iterations"])),
    }
    if key != BASELINE:
        out |= {m: _speedup(base, sub, m, stats) for m in METRICS}
    return out


def cells(table: pd.DataFrame, keys: list[str], stats: dict) -> list[dict]:
    """Every (map or ``pooled``, configuration) row (:func:`cell`), maps in table order."""
    rows = []
    for group in [*dict.fromkeys(table["map_set"]), POOLED]:
        sub = table if group == POOLED else table[table["map_set"] == group]
        sub = _clustered(sub, group)
        base = sub[sub["key"] == BASELINE]
        for key in keys:
            rows.append(
                {
                    "map": group,
                    "configuration": key,
                    **cell(sub[sub["key"] == key], base, key, stats),
                }
            )
    return rows


def against_envelopes(
    table: pd.DataFrame, keys: list[str], envelopes: dict[str, str], stats: dict
) -> list[dict]:
    """Each trained network's configuration against its family's envelope, per map and
    pooled: the speed-up of the network over the envelope (below 1: slower than what a
    perfect heatmap of its idea gives), paired and clustered as :func:`cells`."""
    rows = []
    for group in [*dict.fromkeys(table["map_set"]), POOLED]:
        sub = _clustered(table if group == POOLED else table[table["map_set"] == group], group)
        for key in keys:
            idea = NETWORK_IDEA.get(ConfigKey.parse(key).planner)
            if idea not in envelopes:
                continue
            env = sub[sub["key"] == envelopes[idea]]
            net = sub[sub["key"] == key]
            rows.append(
                {
                    "map": group,
                    "configuration": key,
                    "idea": idea,
                    **{m: _speedup(env, net, m, stats) for m in METRICS},
                }
            )
    return rows


def in_distribution(summary: dict | None, keys: list[str]) -> list[dict]:
    """The configurations' speed-ups over RRT* on the random test maps (the paper
    comparison's ``summary.json``: ``over_rrt_star[metric][stop][key]['random']``) at the
    same stop rule; NaN where that summary has none (another planner list, no random maps)."""
    rows = []
    for key in keys:
        row: dict = {"configuration": key}
        for m in METRICS:
            got = (
                (summary or {})
                .get("over_rrt_star", {})
                .get(m, {})
                .get(STOP, {})
                .get(key, {})
                .get("random")
            )
            row[m] = {r: float(got[r]) if got else math.nan for r in READ}
        rows.append(row)
    return rows


def pooled_caution(n_maps: int) -> str:
    """What the pooled interval over ``n_maps`` maps can support, in one sentence."""
    if n_maps < 2:
        return "One map: the pooled numbers are that map's; nothing here speaks for other maps."
    if n_maps < FEW_CLUSTERS:
        return (
            f"The pooled interval resamples {n_maps} maps: it describes these {n_maps} "
            f"maps, not maps in general, and a cluster bootstrap over fewer than "
            f"{FEW_CLUSTERS} clusters gives intervals narrower than their level "
            "promises; read it as the spread among these maps."
        )
    return f"The pooled interval resamples {n_maps} maps (clusters)."


def analyze(
    table: pd.DataFrame,
    keys: list[str],
    envelopes: dict[str, str],
    maps: dict,
    settings: dict,
    paper_summary: dict | None,
) -> dict:
    """The study's summary (module doc) of its trial ``table`` (configurations ``keys``;
    ``maps``: name -> facts; ``settings``: eps, tau, level, bootstrap, seed, budgets...)."""
    stats = {
        "bootstrap": settings["bootstrap"],
        "level": settings["level"],
        "seed": settings["seed"],
    }
    learned = [k for k in keys if k != BASELINE and k not in envelopes.values()]
    return {
        "settings": settings,
        "maps": maps,
        "keys": keys,
        "names": config_names(keys, envelopes),
        "envelopes": envelopes,
        "cells": cells(table, keys, stats),
        "against_envelopes": against_envelopes(table, learned, envelopes, stats),
        "in_distribution": in_distribution(paper_summary, learned),
        "caution": pooled_caution(len(maps)),
    }
