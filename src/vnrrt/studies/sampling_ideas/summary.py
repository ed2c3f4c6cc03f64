"""Statistics of the sampling-ideas study (:mod:`vnrrt.studies.sampling_ideas.design`),
computed once (stage ``ideas``) as plain JSON-able data (``paths.ideas_summary``) for the
report and the figures.

Every speed-up is the paired, clustered one of :func:`vnrrt.evaluation.stats.compare`: the
geometric mean over instances of median(baseline) / median(planner), with its bootstrap CI;
against RRT* in the same regime cell (and under the same obstacle rule), or between two
configurations (an envelope against another, a blend weight against w = 0, a network against
its family's envelope).
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd

from vnrrt.evaluation.keys import ConfigKey, label
from vnrrt.studies.sampling_ideas import design as d
from vnrrt.studies.sampling_ideas.distinct import effective_keys, groups
from vnrrt.studies.sampling_ideas.edges import envelope_edges
from vnrrt.studies.sampling_ideas.per_cell import own_rows
from vnrrt.studies.sampling_ideas.rows import (
    METRICS,
    blend_rows,
    by_configuration,
    cell_rows,
    compare_pair,
    envelope_rows,
    network_rows,
    quality_rows,
    w0_answer,
)
from vnrrt.studies.sampling_ideas.selection import by_cell


def sweep_columns(rows: list[dict]) -> list[str]:
    """The configurations of ``rows`` (dicts with ``regime`` and ``configuration``) run in
    every cell, in first-seen order: the regime sweep's, without the protocol cell's extra
    ones (the quality curve's and the other obstacle rule's, shown in sections of their
    own); all of them when there is one cell."""
    by: dict[str, set] = {}
    for r in rows:
        by.setdefault(r["configuration"], set()).add(r["regime"])
    cells = set().union(*by.values()) if by else set()
    return [c for c, seen in by.items() if seen == cells]


def flat(cells: list[dict], metric: str) -> list[dict]:
    """The cell rows with a speed-up, that metric's speed-up and CI flattened (figures)."""
    keep = ("regime", "stop", "configuration", "success_rate", "median_ms")
    return [{**{k: r[k] for k in keep}, **r[metric]} for r in cells if metric in r]


def placed(cells: list[dict]) -> list[dict]:
    """The trained networks on the quality curve: the protocol cell's network
    configurations (not informed, the default obstacle rule) with their heatmaps' mass near
    the target in multiples of a uniform map's, per stop rule and metric."""
    out = []
    for r in cells:
        key = ConfigKey.parse(r["configuration"])
        if r["regime"] != d.PROTOCOL or key.named_source or not r["source"]:
            continue
        if key.informed or key.free or not (r["heat_mass"] and r["uniform_mass"]):
            continue
        x = r["heat_mass"] / r["uniform_mass"]
        out += [
            {
                "stop": r["stop"],
                "configuration": r["configuration"],
                "metric": m,
                "heat_mass": r["heat_mass"],
                "x_uniform": x,
                **r[m],
            }
            for m in METRICS
            if m in r
        ]
    return out


def regime_claims(rows: list[dict], pairs: list[tuple[str, str]], table, boot) -> list[dict]:
    """For each (planner, baseline) of the paper's optimal-solution claims and each optimal
    stop rule: the cells where its sign holds (CI above 1), is reversed, or is unclear."""
    g, out = by_configuration(table), []
    cells = list(dict.fromkeys(r["regime"] for r in rows))
    for plan_key, base_key in pairs:
        for stop in ("optimal", "optimal_any_angle"):
            hit = {"holds": [], "reversed": [], "unclear": []}
            for cell in cells:
                base, plan = g.get((cell, stop, base_key)), g.get((cell, stop, plan_key))
                if base is None or plan is None:
                    continue
                s = compare_pair(base, plan, "time_to_stop", boot)
                where = (
                    "holds" if s["ci_low"] > 1 else "reversed" if s["ci_high"] < 1 else "unclear"
                )
                hit[where].append(cell)
            if any(hit.values()):
                text = f"{label(plan_key)} faster than {label(base_key)}"
                out.append(
                    {"claim": text, "planner": plan_key, "baseline": base_key, "stop": stop, **hit}
                )
    return out


def distinct_summary(ev: pd.DataFrame, study: dict, envelopes: dict, pairs: list, settings: dict,
                     free: dict[int, int] | None) -> dict:  # fmt: skip
    """Per optimal stop rule, the regime cells counted once per distinct setting
    (:mod:`.distinct`, from that stop's runs of the configurations every cell ran):
    ``groups`` (representative -> cells), and the envelope comparisons and claims of the
    representatives at the Bonferroni level over the distinct cells (``level``), from enough
    resamples that each tail holds ``settings["tail_draws"]`` draws (``bootstrap``)."""
    cells = {d.PROTOCOL: study["protocol"], **d.regime_cells(study["regime"], study["protocol"])}
    settings_of = _settings_of(cells, ev)
    shared = set.intersection(*(set(t["key"]) for _, t in ev.groupby("regime", sort=False)))
    tails = int(settings.get("tail_draws", 1))
    out = {"free_cells": free is not None, "stops": {}}
    for stop in ("optimal", "optimal_any_angle"):
        runs = ev[ev["stop"] == stop]
        if runs.empty:
            continue
        found = groups(effective_keys(runs[runs["key"].isin(shared)], settings_of, free))
        strict = 1.0 - (1.0 - float(settings["level"])) / max(len(found), 1)
        n_boot = max(int(settings["bootstrap"]), math.ceil(tails / ((1 - strict) / 2) - 1e-6))
        reps = runs[runs["regime"].isin(found)]
        rows, boot = [{"regime": c} for c in found], (n_boot, strict)
        out["stops"][stop] = {
            "groups": found, "level": strict, "bootstrap": n_boot,
            "envelopes": envelope_rows(reps, envelopes, boot),
            "regime_claims": regime_claims(rows, pairs, reps, boot),
        }  # fmt: skip
    return out


def _settings_of(cells: dict, ev: pd.DataFrame) -> dict:
    """Each evaluated cell's settings; a cell of an older design (not in ``cells``) by its
    label (``eta=5 radius=shrinking*0.5 goal=inf``)."""
    return {c: cells.get(c) or d.cell_of_label(c) for c in dict.fromkeys(ev["regime"])}


def analyze_study(tables: dict, study: dict, pairs: list[tuple[str, str]], settings: dict,
                  free: dict[int, int] | None = None) -> dict:  # fmt: skip
    """The whole summary: ``tables`` the merged selection (``oracle``) and evaluation
    (``regime``) trials; ``study`` the ``oracle``, ``regime`` and ``ev`` (eval) sections, the
    ``protocol`` cell's planner settings and the networks' ``targets``; ``settings`` (kept
    for the readers) at least ``bootstrap``, ``level`` and ``tail_draws``; ``free``: each
    instance's free cells (the distinct-cell rule, :mod:`.distinct`; None: settings only)."""
    oc, rc = study["oracle"], study["regime"]
    boot = (int(settings["bootstrap"]), float(settings["level"]))
    sel, ev = tables["oracle"], tables["regime"]
    speedups, envelopes, own = by_cell(sel, d.family_members(oc, study["tau"]))
    cells = cell_rows(ev, boot) if len(ev) else []
    blends = blend_rows(ev, envelopes, oc.blend_weights, boot) if len(ev) else []

    def pair(base: pd.DataFrame, plan: pd.DataFrame) -> dict:
        return {m: compare_pair(base, plan, m, boot) for m in METRICS}

    return {
        "settings": settings,
        "selection": {
            "speedups": speedups,
            "envelopes": envelopes,
            "edges": envelope_edges(envelopes, oc),
            "cells": own,
            "instances": int(sel["instance"].nunique()),
            "maps": sorted(int(c) for c in sel["cluster"].unique()),
        },
        "cells": cells,
        "envelopes": envelope_rows(ev, envelopes, boot) if len(ev) else [],
        "own": own_rows(ev, envelopes, own, pair) if len(ev) else [],
        "blend": blends,
        "w0": w0_answer(blends),
        "networks": network_rows(ev, envelopes, study.get("targets", {}), boot) if len(ev) else [],
        "curves": quality_rows(cells, oc, envelopes),
        "regime": flat(cells, "time_to_stop"),
        "placed": placed(cells),
        "regime_claims": regime_claims(cells, pairs, ev, boot) if len(ev) else [],
        "instances": int(ev["instance"].nunique()) if len(ev) else 0,
        "maps": sorted(int(c) for c in ev["cluster"].unique()) if len(ev) else [],
        "cell_names": list(dict.fromkeys(ev["regime"])) if len(ev) else [],
        "regimes": d.regime_cells(rc, study["protocol"]) if rc else {},
        "distinct": distinct_summary(ev, study, envelopes, pairs, settings, free)
        if len(ev) and rc
        else {},
    }


def as_json(obj):
    """NaN -> None in nested rows (JSON null)."""
    if isinstance(obj, dict):
        return {k: as_json(v) for k, v in obj.items()}
    if isinstance(obj, list):
        return [as_json(v) for v in obj]
    if isinstance(obj, float) and np.isnan(obj):
        return None
    return obj
