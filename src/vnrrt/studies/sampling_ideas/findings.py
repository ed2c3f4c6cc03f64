"""The conclusion of ``reports/sampling_ideas.md``, computed from the summary's numbers
(:func:`vnrrt.studies.sampling_ideas.summary.analyze_study`): each family's envelope, the
turning-point families against the path envelope (in the protocol's cell and per distinct
regime cell, corrected over the cells), the blend's weight, the trained networks against
their envelopes, the heatmap quality each idea needs and the networks' verdicts per cell.
Every setting it names comes from the summary's ``settings``."""

from __future__ import annotations

import math

from vnrrt.evaluation.keys import label
from vnrrt.names import stop_name
from vnrrt.studies.sampling_ideas.design import PROTOCOL
from vnrrt.studies.sampling_ideas.edges import edge_note
from vnrrt.studies.sampling_ideas.per_cell import own_finding

IDEAS = ("path", "vertex", "taut_vertex", "masked_vertex", "blend", "control")  # shown in order
VERTEX_IDEAS = {  # the turning-point families, each against the path envelope in the conclusion
    "vertex": "near the A* path's vertices (the vertex envelope: the staircase's turns)",
    "taut_vertex": "near the true turning points (the taut-vertex envelope: the exact "
    "optimum's corners)",
    "masked_vertex": "as M-VNRRT* with a perfect vertex heatmap (the masked-vertex envelope: "
    "its mask on the vertex oracle, the bound of the masked claims)",
}
OPTIMAL_STOPS = ("optimal", "optimal_any_angle")
OWN_TEXT = (
    "Each family's member also selected in each regime cell, on the selection instances' runs "
    "in that cell (`oracle.per_cell`), and run there on the evaluation instances: fewer "
    "iterations than RRT*, than the protocol cell's selection (in that cell) and than the "
    "cell's own path envelope."
)


def ideas_of(summary: dict) -> list[str]:
    """The families with an envelope under some stop rule: :data:`IDEAS` first, in order,
    then any other."""
    found = dict.fromkeys(i for per in summary["selection"]["envelopes"].values() for i in per)
    return [i for i in IDEAS if i in found] + [i for i in found if i not in IDEAS]


def speedup_text(s: dict | None) -> str:
    if not s or s.get("speedup") is None or not math.isfinite(s["speedup"]):
        return "—"
    lo, hi = s.get("ci_low"), s.get("ci_high")
    if lo is None or not math.isfinite(lo):
        return f"{s['speedup']:.2f}x"
    return f"{s['speedup']:.2f}x [{lo:.2f}, {hi:.2f}]"


def pct(v) -> str:
    return "—" if v is None or not math.isfinite(v) else f"{100 * v:.1f}%"


def _word(s: dict, better: str, worse: str, same: str) -> str:
    """``better`` when the CI lies above 1, ``worse`` below, else ``same`` (never a gain
    for an interval that contains 1)."""
    if s["ci_low"] is not None and s["ci_low"] > 1:
        return better
    if s["ci_high"] is not None and s["ci_high"] < 1:
        return worse
    return same


def cell_row(summary: dict, cell: str, stop: str, text: str | None) -> dict | None:
    return next(
        (
            r
            for r in summary["cells"]
            if (r["regime"], r["stop"], r["configuration"]) == (cell, stop, text)
        ),
        None,
    )


def _envelope_findings(summary: dict, stop: str, eps: float) -> list[str]:
    env = summary["selection"]["envelopes"].get(stop, {})
    rows = {
        r["idea"]: r for r in summary["envelopes"] if r["regime"] == PROTOCOL and r["stop"] == stop
    }
    out, ideas = [], ideas_of(summary)
    cells = {i: cell_row(summary, PROTOCOL, stop, env.get(i)) for i in ideas}
    edges = summary["selection"].get("edges", {}).get(stop, {})
    said = "; ".join(f"{i} {speedup_text(cells[i].get('iterations'))}{edge_note(edges.get(i))}"
                     for i in ideas if cells[i])  # fmt: skip
    if said:
        out.append(
            f"Envelopes ({stop_name(stop, eps)}, the protocol's cell, fewer iterations "
            f"than RRT*): {said}."
        )
    for idea, how in VERTEX_IDEAS.items():
        if idea in rows:
            v = rows[idea]["iterations"]
            word = _word(v, "fewer iterations than", "more iterations than",
                         "no clear difference from")  # fmt: skip
            out.append(
                f"Sampling {how} needs {word} sampling near the path (the path envelope): "
                f"{speedup_text(v)} ({stop_name(stop, eps)})."
            )
    return out


def _distinct(summary: dict, stop: str) -> dict:
    """A stop rule's distinct cells and their readings (:func:`~.summary.distinct_summary`),
    or every cell's at the per-cell level where the summary has none."""
    d = (summary.get("distinct") or {}).get("stops", {}).get(stop)
    if d:
        return d
    cells = summary.get("cell_names", [])
    claims = [c for c in summary.get("regime_claims", []) if c["stop"] == stop]
    return {"groups": {c: [c] for c in cells}, "envelopes": summary["envelopes"],
            "regime_claims": claims, "level": None}  # fmt: skip


def cells_by_winner(summary: dict, stop: str, idea: str = "vertex") -> dict[str, list[str]]:
    """``{"path": cells, idea: cells, "unclear": cells}``: the distinct regime cells (in the
    study's order; :mod:`.distinct`) where the path envelope needs clearly fewer iterations
    than the ``idea`` envelope (their paired ratio's CI, corrected over the distinct cells,
    below 1), where ``idea``'s needs clearly fewer (CI above 1), and the others."""
    d = _distinct(summary, stop)
    out: dict[str, list[str]] = {"path": [], idea: [], "unclear": []}
    rows = {
        r["regime"]: r["iterations"]
        for r in d["envelopes"]
        if r["stop"] == stop and r["idea"] == idea
    }
    for cell in d["groups"]:
        if cell in rows:
            out[_word(rows[cell], idea, "path", "unclear")].append(cell)
    return out


def _corrected(summary: dict, stop: str) -> str:
    """How the per-cell counts were made: over distinct cells, Bonferroni-corrected."""
    d = _distinct(summary, stop)
    if d["level"] is None:
        return ""
    same = [f"{' = '.join(cells)}" for cells in d["groups"].values() if len(cells) > 1]
    merged = f"; the same runs: {'; '.join(same)}" if same else ""
    return (f" (counted over {len(d['groups'])} distinct cells{merged}; each interval at "
            f"{d['level']:.3%}, Bonferroni over the distinct cells)")  # fmt: skip


def _winner_finding(summary: dict, stop: str, eps: float) -> list[str]:
    """Per turning-point family (:data:`VERTEX_IDEAS`): the distinct cells its envelope or
    the path envelope wins (:func:`cells_by_winner`)."""

    def named(cells: list[str]) -> str:
        return f" ({'; '.join(cells)})" if cells else ""

    out = []
    for idea in VERTEX_IDEAS:
        won = cells_by_winner(summary, stop, idea)
        n = sum(len(v) for v in won.values())
        if n:
            out.append(
                f"Path envelope against {idea} envelope, per regime cell "
                f"({stop_name(stop, eps)}): the path envelope needs clearly fewer iterations "
                f"in {len(won['path'])} of {n} cells{named(won['path'])}; the {idea} envelope "
                f"in {len(won[idea])}{named(won[idea])}; no clear difference in "
                f"{len(won['unclear'])}{_corrected(summary, stop)}."
            )
    return out


def conclusion(summary: dict) -> list[str]:
    """Plain-language findings computed from the summary (module doc)."""
    st, out = summary["settings"], []
    eps = st["eps"]
    for stop in OPTIMAL_STOPS:
        out += _envelope_findings(summary, stop, eps)
        out += _winner_finding(summary, stop, eps)
        out += own_finding(summary.get("own", []), stop, eps, _distinct(summary, stop)["groups"])
        w0 = summary["w0"].get(stop)
        if w0:
            out.append(
                f"Does w = 0 (the path oracle) win at every step size ({stop_name(stop, eps)})? "
                + (
                    "Yes: no blend with w > 0 needs clearly fewer iterations in any cell."
                    if w0["w0_wins_everywhere"]
                    else "No: a blend with w > 0 needs clearly fewer iterations in "
                    + ", ".join(w0["blend_wins"])
                    + "."
                )
            )
    for r in summary["networks"]:
        if r["stop"] != "optimal":
            continue
        s = r["iterations"]
        word = _word(
            s,
            "above its family's envelope (the family is incomplete: a member "
            "this good was not among the oracles)",
            "below its family's envelope",
            "not clearly different from its family's envelope",
        )
        out.append(
            f"The trained {label(r['configuration'])} is {word}: {speedup_text(s)} of the "
            f"{r['idea']} envelope's iterations saved ({stop_name('optimal', eps)})."
        )
    out += quality_needed(summary, eps)
    claims = [c for stop in OPTIMAL_STOPS for c in _distinct(summary, stop)["regime_claims"]]
    pairs = list(dict.fromkeys((c["planner"], c["baseline"]) for c in claims))
    claims.sort(key=lambda c: (pairs.index((c["planner"], c["baseline"])), c["stop"]))
    for c in claims:
        n = len(c["holds"]) + len(c["reversed"]) + len(c["unclear"])
        out.append(
            f"{c['claim']} ({stop_name(c['stop'], eps)}): holds in {len(c['holds'])} of "
            f"{n} distinct cells, reversed in {len(c['reversed'])}, unclear in "
            f"{len(c['unclear'])}."
        )
    return out


def quality_needed(summary: dict, eps: float) -> list[str]:
    """Per idea: the heatmap quality (mass near the target, x a uniform map's) from which the
    iteration speed-up's CI lies above 1 at that quality and every better one, from the
    q > 0 points; "none needed" when q = 0 (a uniform map) already clears."""
    out = []
    for idea in ("path", "vertex"):
        rows = [
            r
            for r in summary["curves"]
            if r["idea"] == idea
            and r["stop"] == "optimal"
            and r["metric"] == "iterations"
            and r["own"]
        ]
        if not rows:
            continue
        zero = [r for r in rows if r["q"] == 0.0]
        if zero and zero[0]["ci_low"] is not None and zero[0]["ci_low"] > 1:
            out.append(f"{idea} oracle: none needed (a uniform map already clears RRT*).")
            continue
        need = None
        for r in sorted((r for r in rows if r["q"] > 0), key=lambda r: -r["q"]):
            if r["ci_low"] is None or r["ci_low"] <= 1:
                break
            need = r
        said = (
            "never at these q"
            if need is None
            else (f"{need['x_uniform']:.1f}x a uniform map's mass (q = {need['q']:g})")
        )
        out.append(
            f"Heatmap quality the {idea} idea needs for a clear gain over RRT* in "
            f"iterations ({stop_name('optimal', eps)}; its envelope diluted): {said}."
        )
    return out
