"""Each oracle family's best member, chosen on the selection instances (never on the
evaluation instances it is reported on): per stop rule, the member that saves RRT* the most
iterations (the geometric mean over instances of median(RRT*) / median(member) iterations,
:func:`vnrrt.evaluation.stats.compare`'s point estimate). Ties keep the first member in the
order of :func:`vnrrt.studies.sampling_ideas.design.family_members`. The selection table's
``regime`` column names the cell a row ran in: ``""`` the protocol's (the envelopes), any
other a regime cell's own selection (``oracle.per_cell``, :func:`by_cell`)."""

from __future__ import annotations

import pandas as pd

from vnrrt.evaluation.stats import compare

BASELINE = "rrt_star"
PROTOCOL_ROWS = ""  # the regime label of the protocol cell's selection rows
SELECTION_METRIC = "iterations"


def member_speedups(table: pd.DataFrame, members: dict[str, list]) -> dict:
    """``{stop: {idea: {key text: speed-up}}}`` of every family member over RRT* on the
    selection instances (``table``: the selection trials; ``members``: ``{idea: keys}``)."""
    out: dict = {}
    for stop, sub in table.groupby("stop", sort=False):
        base = sub[sub["key"] == BASELINE]
        by_key = dict(tuple(sub.groupby("key", sort=False)))
        for idea, keys in members.items():
            cell = out.setdefault(stop, {}).setdefault(idea, {})
            for key in keys:
                rows = by_key.get(key.text)
                if rows is not None and not base.empty:
                    cell[key.text] = compare(base, rows, SELECTION_METRIC, n_boot=1).speedup
    return out


def select(speedups: dict) -> dict:
    """``{stop: {idea: key text}}``: each family's envelope, its fastest member
    (``speedups``: :func:`member_speedups`)."""
    out: dict = {}
    for stop, per_idea in speedups.items():
        for idea, cells in per_idea.items():
            order = list(cells)
            if order:
                best = max(order, key=lambda k: (cells[k], -order.index(k)))
                out.setdefault(stop, {})[idea] = best
    return out


def by_cell(table: pd.DataFrame, members: dict[str, list]) -> tuple[dict, dict, dict]:
    """``(speed-ups, envelopes, own)`` of a selection table: the protocol cell's member
    speed-ups and envelopes (:func:`member_speedups`, :func:`select`) and ``own``: ``{cell:
    {stop: {idea: key text}}}``, each other cell's envelopes, selected on its own rows."""
    cells = dict(tuple(table.groupby("regime", sort=False)))
    here = cells.pop(PROTOCOL_ROWS, table.iloc[:0])
    speedups = member_speedups(here, members)
    own = {cell: select(member_speedups(rows, members)) for cell, rows in cells.items()}
    return speedups, select(speedups), own
