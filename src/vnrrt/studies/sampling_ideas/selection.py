"""Each oracle family's best member, chosen on the selection instances (never on the
evaluation instances it is reported on): per stop rule, the member that saves RRT* the most
iterations (the geometric mean over instances of median(RRT*) / median(member) iterations,
:func:`vnrrt.evaluation.stats.compare`'s point estimate). Ties keep the first member in the
order of :func:`vnrrt.studies.sampling_ideas.design.family_members`."""

from __future__ import annotations

import pandas as pd

from vnrrt.evaluation.stats import compare

BASELINE = "rrt_star"
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
