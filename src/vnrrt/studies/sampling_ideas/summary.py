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
from vnrrt.evaluation.sources import OracleSource
from vnrrt.evaluation.stats import compare
from vnrrt.studies.sampling_ideas import design as d
from vnrrt.studies.sampling_ideas.distinct import effective_keys, groups
from vnrrt.studies.sampling_ideas.edges import envelope_edges
from vnrrt.studies.sampling_ideas.per_cell import own_rows
from vnrrt.studies.sampling_ideas.selection import by_cell

BASELINE = ConfigKey("rrt_star")
METRICS = ("iterations", "time_to_stop")
IDEA_OF_TARGET = {"vertex": "vertex", "path": "path"}  # a network's target -> its family


def _cmp(base: pd.DataFrame, plan: pd.DataFrame, metric: str, boot: tuple) -> dict:
    c = compare(base, plan, metric, n_boot=boot[0], level=boot[1])
    return {"speedup": c.speedup, "ci_low": c.ci_low, "ci_high": c.ci_high}


def _groups(table: pd.DataFrame) -> dict:
    """``{(regime cell, stop, key): rows}`` of an evaluation table."""
    return {k: g for k, g in table.groupby(["regime", "stop", "key"], sort=False)}


def cell_rows(table: pd.DataFrame, boot: tuple) -> list[dict]:
    """Per cell, stop rule and configuration: success, medians, heatmap masses and the
    speed-ups over RRT* under the same obstacle rule (iterations, time) with CIs."""
    g, out = _groups(table), []
    for (cell, stop, text), rows in g.items():
        key = ConfigKey.parse(text)
        base = g.get((cell, stop, BASELINE.with_free(key.free).text))
        row = {
            "regime": cell,
            "stop": stop,
            "configuration": text,
            "source": str(rows["source"].iloc[0]),
            "success_rate": float(rows["success"].mean()),
            "cut_by_time": int((rows["stop_reason"] == "max_seconds").sum()),
            "cut_by_cap": int((rows["run_stop_reason"] == "max_seconds").sum()),
            "median_ms": float(1e3 * rows["time_to_stop"].median()),
            "median_iterations": float(rows["iterations"].median()),
            "heat_mass": _mean(rows["heat_mass"]),
            "uniform_mass": _mean(rows["uniform_mass"]),
        }
        if base is not None and text != base["key"].iloc[0]:
            row |= {m: _cmp(base, rows, m, boot) for m in METRICS}
        out.append(row)
    return out


def _mean(values: pd.Series) -> float | None:
    v = values.dropna()
    return float(v.mean()) if len(v) else None


def envelope_rows(table: pd.DataFrame, envelopes: dict, boot: tuple) -> list[dict]:
    """Per cell and stop rule: every other family's envelope (the vertex, taut-vertex and
    masked-vertex ones, the blend, the control) against the path envelope (paired, iterations
    and time): above 1, faster than sampling near the path."""
    g, out = _groups(table), []
    for (cell, stop), _ in table.groupby(["regime", "stop"], sort=False):
        env = envelopes.get(stop, {})
        path = g.get((cell, stop, env.get("path")))
        for idea in (i for i in env if i != "path"):
            rows = g.get((cell, stop, env.get(idea)))
            if path is not None and rows is not None:
                out.append(
                    {
                        "regime": cell,
                        "stop": stop,
                        "idea": idea,
                        "against": "path",
                        **{m: _cmp(path, rows, m, boot) for m in METRICS},
                    }
                )
    return out


def blend_rows(table: pd.DataFrame, envelopes: dict, weights: list[float], boot: tuple) -> list:
    """Per cell and stop rule, the blend at every weight w against w = 0 (the path oracle at
    the blend envelope's blur and mix): above 1, the vertex share helps."""
    g, out = _groups(table), []
    for (cell, stop), _ in table.groupby(["regime", "stop"], sort=False):
        chosen = envelopes.get(stop, {}).get("blend")
        if chosen is None:
            continue
        zero = g.get((cell, stop, d.blend_at(ConfigKey.parse(chosen), 0.0).text))
        for w in weights:
            rows = g.get((cell, stop, d.blend_at(ConfigKey.parse(chosen), w).text))
            if zero is not None and rows is not None and w != 0.0:
                out.append(
                    {
                        "regime": cell,
                        "stop": stop,
                        "w": w,
                        **{m: _cmp(zero, rows, m, boot) for m in METRICS},
                    }
                )
    return out


def w0_answer(blends: list[dict]) -> dict:
    """``{stop: {"w0_wins_everywhere": bool, "blend_wins": [cells]}}``: whether no blend with
    w > 0 needs clearly fewer iterations than w = 0 (CI above 1) in any cell."""
    out: dict = {}
    for b in blends:
        cell = out.setdefault(b["stop"], {"w0_wins_everywhere": True, "blend_wins": []})
        if b["iterations"]["ci_low"] > 1:
            cell["w0_wins_everywhere"] = False
            cell["blend_wins"].append(f"{b['regime']} (w={b['w']:g})")
    return out


def network_rows(table: pd.DataFrame, envelopes: dict, targets: dict, boot: tuple) -> list:
    """Each trained network against its family's envelope in the protocol's cell (a network
    above its envelope means the family is incomplete): NRRT* the path envelope's, VNRRT* the
    vertex envelope's, M-VNRRT* (its own mask) the masked-vertex envelope's at its tau."""
    g, out = _groups(table), []
    for (cell, stop, text), rows in g.items():
        key = ConfigKey.parse(text)
        idea = IDEA_OF_TARGET.get(targets.get(str(rows["source"].iloc[0])))
        if key.tau is not None:
            idea = None if key.mask else d.MASKED_IDEA
        if cell != d.PROTOCOL or key.named_source or key.free or idea is None:
            continue
        chosen = envelopes.get(stop, {}).get(idea)
        env = g.get((cell, stop, chosen))
        if env is not None and not key.informed and ConfigKey.parse(chosen).tau == key.tau:
            out.append(
                {
                    "stop": stop,
                    "configuration": text,
                    "idea": idea,
                    **{m: _cmp(env, rows, m, boot) for m in METRICS},
                }
            )
    return out


def quality_rows(cells: list[dict], oc, envelopes: dict) -> list[dict]:
    """The quality curve: the protocol cell's diluted envelopes, x = heatmap mass near the
    target in multiples of a uniform map's (``oc``: the ``oracle`` section); ``member``: the
    envelope diluted (signal fraction 1), ``own``: it is the envelope chosen for the row's
    stop rule (``envelopes``: ``{stop: {idea: key text}}``; the others are every other stop
    rule's, run under this one)."""
    out = []
    for r in cells:
        key = ConfigKey.parse(r["configuration"])
        idea = d.idea_of(key, oc)
        if r["regime"] != d.PROTOCOL or idea not in d.QUALITY_IDEAS or key.free:
            continue
        q = OracleSource.parse(key.source).q
        member = d.diluted(key, 1.0).text
        own = envelopes.get(r["stop"], {}).get(idea) == member
        x = r["heat_mass"] / r["uniform_mass"] if r["heat_mass"] and r["uniform_mass"] else None
        for m in METRICS:
            if m in r:
                out.append(
                    {
                        "stop": r["stop"],
                        "idea": idea,
                        "configuration": r["configuration"],
                        "member": member,
                        "own": own,
                        "q": q,
                        "heat_mass": r["heat_mass"],
                        "uniform_mass": r["uniform_mass"],
                        "x_uniform": x,
                        "metric": m,
                        **r[m],
                    }
                )
    return out


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
    g, out = _groups(table), []
    cells = list(dict.fromkeys(r["regime"] for r in rows))
    for plan_key, base_key in pairs:
        for stop in ("optimal", "optimal_any_angle"):
            hit = {"holds": [], "reversed": [], "unclear": []}
            for cell in cells:
                base, plan = g.get((cell, stop, base_key)), g.get((cell, stop, plan_key))
                if base is None or plan is None:
                    continue
                s = _cmp(base, plan, "time_to_stop", boot)
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
        "own": own_rows(ev, envelopes, own, lambda b, p: {m: _cmp(b, p, m, boot) for m in METRICS})
        if len(ev)
        else [],
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
