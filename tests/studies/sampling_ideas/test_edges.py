"""Envelope edge flags: on a grid whose best member is its largest value the envelope is
flagged (the best measured member), an interior best member is a bound, and the report says
which."""

import math

from vnrrt.evaluation.config import OracleConfig
from vnrrt.studies.sampling_ideas import design
from vnrrt.studies.sampling_ideas.edges import axis_edge, edge_note, envelope_edges
from vnrrt.studies.sampling_ideas.report import selection_table
from vnrrt.studies.sampling_ideas.selection import select


def _oc(mixes, sigmas) -> OracleConfig:
    return OracleConfig(families={"path": ["oracle_path"], "vertex": ["oracle_vertex"]},
                        planners={"path": "nrrt_star"}, mixes=mixes, sigmas=sigmas,
                        blend_weights=[0.0, 0.5, 1.0])  # fmt: skip


def _speedups(oc: OracleConfig, score) -> dict:
    """``{stop: {idea: {key: score(key)}}}`` over every family member (a synthetic
    selection: the speed-up a member would have measured)."""
    members = design.family_members(oc, tau=0.5)
    return {"optimal": {i: {k.text: score(k) for k in keys} for i, keys in members.items()}}


def test_a_best_member_at_the_largest_mix_is_flagged():
    oc = _oc([0.25, 0.5, 0.75], [1.0, 4.0, 16.0])
    # still climbing at the largest mix; the blur peaks inside the grid
    envelopes = select(_speedups(oc, lambda k: 10 * k.mix - abs(math.log(_sigma(k) / 4))))
    chosen = envelopes["optimal"]["vertex"]
    assert "~0.75" in chosen and "@s4" in chosen  # the grid's largest mix, its middle blur
    edges = envelope_edges(envelopes, oc)["optimal"]
    assert edges["vertex"] == ["mix 0.75, the largest tried (0.25-0.75)"]
    assert edge_note(edges["vertex"]).startswith(" (best measured member: mix 0.75")
    sel = {"speedups": _speedups(oc, lambda k: 1.0), "envelopes": envelopes}
    summary = {"selection": sel | {"edges": envelope_edges(envelopes, oc)}}
    row = next(ln for ln in selection_table(summary, "optimal").splitlines() if "| vertex |" in ln)
    assert row.endswith("mix 0.75, the largest tried (0.25-0.75): the best measured member |")


def test_an_interior_best_member_is_a_bound():
    oc = _oc([0.25, 0.5, 0.75], [1.0, 4.0, 16.0])
    envelopes = select(_speedups(oc, lambda k: -abs(k.mix - 0.5) - abs(_sigma(k) - 4)))
    edges = envelope_edges(envelopes, oc)["optimal"]
    assert edges["path"] == [] and edge_note(edges["path"]) == " (interior: a bound)"


def test_the_end_of_a_domain_is_no_edge():
    assert axis_edge("mix", 1.0, [0.5, 0.75, 1.0]) is None  # mix cannot exceed 1
    assert axis_edge("blur sigma (px)", 0.0, [0.0, 2.0]) is None  # nor blur go below 0
    assert axis_edge("blur sigma (px)", 1.0, [1.0, 2.0]) == (
        "blur sigma (px) 1, the smallest tried (1-2)"
    )
    assert axis_edge("mix", 0.5, [0.5]) == "mix 0.5, the largest tried (only 0.5)"


def _sigma(key) -> float:
    return float(key.source.split("@s")[1].split("@")[0])
