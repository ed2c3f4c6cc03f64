"""The selection in each regime cell (``oracle.per_cell``): besides the protocol cell's
envelopes, run everywhere, each family's member is also selected in every other regime cell on
that cell's own selection runs (:func:`~vnrrt.studies.sampling_ideas.selection.by_cell`) and
run on the evaluation instances of that cell. Read here per cell, stop rule and family: the
cell's own envelope against RRT*, against the protocol's envelope (above 1: selecting in the
cell saved more iterations) and, for the other families, against the cell's own path envelope.
Speed-ups as everywhere in the study (:func:`vnrrt.evaluation.stats.compare`)."""

from __future__ import annotations

import pandas as pd

from vnrrt.evaluation.keys import label
from vnrrt.names import stop_name

METRICS = ("iterations", "time_to_stop")


def own_rows(table: pd.DataFrame, envelopes: dict, own: dict, compare_with) -> list[dict]:
    """Per cell of ``own`` (``{cell: {stop: {idea: key text}}}``), stop and family: the
    readings of the module doc from the evaluation ``table``; ``envelopes``: the protocol
    cell's; ``compare_with(base rows, plan rows)``: ``{metric: {speedup, ci_low, ci_high}}``."""
    g = {k: rows for k, rows in table.groupby(["regime", "stop", "key"], sort=False)}
    out = []
    for cell, per_stop in own.items():
        for stop, chosen in per_stop.items():
            base = g.get((cell, stop, "rrt_star"))
            path = g.get((cell, stop, chosen.get("path")))
            for idea, text in chosen.items():
                rows = g.get((cell, stop, text))
                if rows is None or base is None:
                    continue
                theirs = envelopes.get(stop, {}).get(idea)
                protocol = g.get((cell, stop, theirs))
                row = {"regime": cell, "stop": stop, "idea": idea, "configuration": text,
                       "protocol_choice": theirs, "over_rrt": compare_with(base, rows)}  # fmt: skip
                if protocol is not None and theirs != text:
                    row["vs_protocol"] = compare_with(protocol, rows)
                if path is not None and idea != "path":
                    row["vs_path"] = compare_with(path, rows)
                out.append(row)
    return out


def _x(s: dict | None) -> str:
    if not s:
        return "—"
    return f"{s['speedup']:.2f}x [{s['ci_low']:.2f}, {s['ci_high']:.2f}]"


def own_table(rows: list[dict], stop: str) -> str:
    """The readings of one stop rule (module doc), one line per cell and family."""
    mine = [r for r in rows if r["stop"] == stop]
    if not mine:
        return "(not run)"
    lines = [
        "| cell | family | selected in the cell | over RRT* | against the protocol's "
        "selection | against the cell's path envelope |",
        "| --- | --- | --- | --- | --- | --- |",
    ]
    for r in mine:
        same = r["configuration"] == r["protocol_choice"]
        versus = "the same member" if same else _x((r.get("vs_protocol") or {}).get("iterations"))
        lines.append(
            f"| {r['regime']} | {r['idea']} | {label(r['configuration'])} | "
            f"{_x(r['over_rrt'].get('iterations'))} | {versus} | "
            f"{_x((r.get('vs_path') or {}).get('iterations'))} |"
        )
    return "\n".join(lines)


def own_finding(rows: list[dict], stop: str, eps: float, distinct=None) -> list[str]:
    """How often selecting in the cell changed the member and clearly saved more (or fewer)
    iterations than the protocol's selection (CI above or below 1), over the ``distinct``
    cells (:mod:`.distinct`'s representatives; None: every cell)."""
    mine = [r for r in rows if r["stop"] == stop and (distinct is None or r["regime"] in distinct)]
    if not mine:
        return []
    moved = [r for r in mine if r["configuration"] != r["protocol_choice"]]
    its = [r["vs_protocol"]["iterations"] for r in moved if "vs_protocol" in r]
    more = sum(1 for s in its if s["ci_low"] > 1)
    fewer = sum(1 for s in its if s["ci_high"] < 1)
    return [
        f"Selected in each distinct regime cell ({stop_name(stop, eps)}, on the cell's own "
        f"selection runs): {len(moved)} of {len(mine)} (cell, family) envelopes differ from the "
        f"protocol's; {more} of them save clearly more iterations than it on the evaluation "
        f"instances, {fewer} clearly fewer, the rest no clear difference."
    ]
