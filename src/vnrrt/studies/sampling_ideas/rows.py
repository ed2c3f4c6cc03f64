"""The sampling-ideas study's rows (:mod:`.summary` assembles them): per regime cell and
configuration its success, medians and speed-ups over RRT*; the envelopes (each family's best
measured member) against one another; the path-vertex blend against w = 0; the networks
against their family's envelope; and the quality curve. Every speed-up is the paired,
clustered one of :func:`vnrrt.evaluation.stats.compare`.
"""

from __future__ import annotations

import pandas as pd

from vnrrt.evaluation.keys import ConfigKey
from vnrrt.evaluation.sources import OracleSource
from vnrrt.evaluation.stats import compare
from vnrrt.studies.sampling_ideas import design as d

BASELINE = ConfigKey("rrt_star")
METRICS = ("iterations", "time_to_stop")
IDEA_OF_TARGET = {"vertex": "vertex", "path": "path"}  # a network's target -> its family


def compare_pair(base: pd.DataFrame, plan: pd.DataFrame, metric: str, boot: tuple) -> dict:
    c = compare(base, plan, metric, n_boot=boot[0], level=boot[1])
    return {"speedup": c.speedup, "ci_low": c.ci_low, "ci_high": c.ci_high}


def by_configuration(table: pd.DataFrame) -> dict:
    """``{(regime cell, stop, key): rows}`` of an evaluation table."""
    return {k: g for k, g in table.groupby(["regime", "stop", "key"], sort=False)}


def cell_rows(table: pd.DataFrame, boot: tuple) -> list[dict]:
    """Per cell, stop rule and configuration: success, medians, heatmap masses and the
    speed-ups over RRT* under the same obstacle rule (iterations, time) with CIs."""
    g, out = by_configuration(table), []
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
            row |= {m: compare_pair(base, rows, m, boot) for m in METRICS}
        out.append(row)
    return out


def _mean(values: pd.Series) -> float | None:
    v = values.dropna()
    return float(v.mean()) if len(v) else None


def envelope_rows(table: pd.DataFrame, envelopes: dict, boot: tuple) -> list[dict]:
    """Per cell and stop rule: every other family's envelope (the vertex, taut-vertex and
    masked-vertex ones, the blend, the control) against the path envelope (paired, iterations
    and time): above 1, faster than sampling near the path."""
    g, out = by_configuration(table), []
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
                        **{m: compare_pair(path, rows, m, boot) for m in METRICS},
                    }
                )
    return out


def blend_rows(table: pd.DataFrame, envelopes: dict, weights: list[float], boot: tuple) -> list:
    """Per cell and stop rule, the blend at every weight w against w = 0 (the path oracle at
    the blend envelope's blur and mix): above 1, the vertex share helps."""
    g, out = by_configuration(table), []
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
                        **{m: compare_pair(zero, rows, m, boot) for m in METRICS},
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
    g, out = by_configuration(table), []
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
                    **{m: compare_pair(env, rows, m, boot) for m in METRICS},
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
