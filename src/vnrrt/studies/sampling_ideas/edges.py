"""Where an envelope sits on its family's grid.

An envelope is the best *measured* member of a finite family (``oracle.mixes`` x
``oracle.sigmas``, and ``oracle.blend_weights`` for the blend): when the chosen member takes
the largest or smallest value a grid axis tried, and the parameter's domain goes on beyond
it, a better member may lie outside the grid. Such an envelope is flagged and called *the
best measured member*; only an envelope interior on every axis (or at the end of the
parameter's own domain) is read as a bound of its idea.
"""

from __future__ import annotations

import math

from vnrrt.evaluation.keys import ConfigKey
from vnrrt.evaluation.sources import OracleSource

DOMAINS = {"mix": (0.0, 1.0), "blur sigma (px)": (0.0, math.inf), "blend weight": (0.0, 1.0)}
"""Each grid axis's domain: an end of the domain is no edge of the grid."""


def axis_edge(name: str, value: float, grid: list[float]) -> str | None:
    """A description of ``value`` at an edge of ``grid`` (the values axis ``name`` tried)
    that its domain (:data:`DOMAINS`) continues beyond, else None."""
    lo, hi = min(grid), max(grid)
    dom_lo, dom_hi = DOMAINS[name]
    tried = f"{lo:g}-{hi:g}" if lo != hi else f"only {lo:g}"
    if value >= hi and hi < dom_hi:
        return f"{name} {value:g}, the largest tried ({tried})"
    if value <= lo and lo > dom_lo:
        return f"{name} {value:g}, the smallest tried ({tried})"
    return None


def member_edges(text: str, mixes: list[float], sigmas: list[float],
                 weights: list[float]) -> list[str]:  # fmt: skip
    """The grid edges (:func:`axis_edge`) an envelope's key ``text`` sits on: its mix, blur
    and (a blend) weight against the family's grid."""
    key = ConfigKey.parse(text)
    src = OracleSource.parse(key.source)
    axes = [("mix", key.mix, mixes), ("blur sigma (px)", src.sigma, sigmas)]
    if src.w is not None:
        axes.append(("blend weight", src.w, weights))
    found = (axis_edge(n, v, g) for n, v, g in axes if v is not None and g)
    return [e for e in found if e]


def envelope_edges(envelopes: dict, oc) -> dict:
    """``{stop: {idea: [edges]}}`` of every envelope (``envelopes``: ``{stop: {idea: key
    text}}``; ``oc``: the ``oracle`` section); an empty list: interior, a bound."""
    return {
        stop: {
            idea: member_edges(t, oc.mixes, oc.sigmas, oc.blend_weights) for idea, t in per.items()
        }
        for stop, per in envelopes.items()
    }


def edge_note(edges: list[str] | None) -> str:
    """How an envelope is named beside its number: ``(best measured member: mix 0.75, the
    largest tried (0.25-0.75))`` on an edge, ``(interior: a bound)`` otherwise."""
    if edges is None:
        return ""
    if not edges:
        return " (interior: a bound)"
    return f" (best measured member: {', '.join(edges)})"
