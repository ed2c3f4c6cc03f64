"""The selection in each regime cell (``oracle.per_cell``): the selection runs in the protocol's
cell and, switched on, in every distinct regime cell (the optimal stop rules there); each
cell's envelopes come from that cell's rows alone (the protocol's are the same as without the
other cells' rows); the evaluation runs a cell's own envelopes in that cell only; and the
readings compare a cell's own envelope with RRT*, the protocol's selection and the cell's path
envelope, on a synthetic table whose speed-ups are known."""

import dataclasses

import pandas as pd
import pytest

from vnrrt.evaluation.config import Configurations, OracleConfig, RegimeConfig
from vnrrt.planners import PlannerConfig
from vnrrt.studies.sampling_ideas import design as d
from vnrrt.studies.sampling_ideas.per_cell import own_finding, own_rows, own_table
from vnrrt.studies.sampling_ideas.selection import by_cell, member_speedups, select

PROTOCOL = d.protocol_settings(PlannerConfig(eta=10.0))
GRID = RegimeConfig(etas=[10.0, float("inf")], radius_modes=["shrinking"], gamma_factors=[1.0],
                    goal_radii=[None, float("inf")], configurations=["rrt_star"])  # fmt: skip
INF = "eta=inf radius=shrinking goal=eta"
OC = OracleConfig(families={"path": ["oracle_path"], "vertex": ["oracle_vertex"]},
                  planners={"path": "nrrt_star"}, sigmas=[1.0, 4.0], mixes=[0.5],
                  blend_weights=[0.0], per_cell=True)  # fmt: skip


def test_the_selection_runs_in_every_distinct_cell_when_switched_on():
    cells = d.selection_cells(OC, GRID, PROTOCOL)
    # eta=10 goal=eta is the protocol's; at an unlimited step the goal radius is moot
    assert cells == {"": {}, "eta=10 radius=shrinking goal=inf": {"eta": 10.0,
                     "goal_radius": float("inf"), "radius_mode": "shrinking",
                     "gamma_factor": 1.0}, INF: d.regime_cells(GRID, PROTOCOL)[INF]}  # fmt: skip
    assert d.selection_cells(dataclasses.replace(OC, per_cell=False), None, PROTOCOL) == {"": {}}
    with pytest.raises(ValueError, match="regime cells"):
        d.selection_cells(OC, None, PROTOCOL)
    assert set(d.oracle_counts(OC)) == {("random", s) for s in d.STOPS}
    assert set(d.oracle_counts(OC, INF)) == {("random", "optimal"), ("random", "optimal_any_angle")}


def _rows(cell: str, key: str, iterations: list[int], stop: str = "optimal") -> pd.DataFrame:
    n = len(iterations)
    return pd.DataFrame({"regime": cell, "stop": stop, "key": key, "instance": range(n),
                         "cluster": [i // 2 for i in range(n)], "trial": 0, "success": True,
                         "iterations": iterations,
                         "time_to_stop": [i / 1e4 for i in iterations]})  # fmt: skip


def _selection() -> tuple[pd.DataFrame, dict, list[str]]:
    """The protocol's rows favour blur 1, the unlimited step's blur 4 (both families)."""
    members = d.family_members(OC, 0.5)
    texts = [k.text for k in members["path"] + members["vertex"]]
    parts = [_rows(cell, "rrt_star", [1000] * 4) for cell in ("", INF)]
    for t in texts:
        sharp = "@s1]" in t
        parts += [
            _rows("", t, [100 if sharp else 400] * 4),
            _rows(INF, t, [400 if sharp else 50] * 4),
        ]
    return pd.concat(parts), members, texts


def test_each_cell_selects_on_its_own_rows():
    table, members, _ = _selection()
    speedups, envelopes, own = by_cell(table, members)
    alone = member_speedups(table[table["regime"] == ""], members)
    assert speedups == alone and envelopes == select(alone)  # other cells' rows change nothing
    assert envelopes["optimal"]["path"] == "nrrt_star~0.5[oracle_path@s1]"
    assert set(own) == {INF} and own[INF]["optimal"]["path"] == "nrrt_star~0.5[oracle_path@s4]"
    assert own[INF]["optimal"]["vertex"] == "vnrrt_star~0.5[oracle_vertex@s4]"
    ev = Configurations(sources={"nrrt_star": "a", "vnrrt_star": "b", "m_vnrrt_star": "b"})
    keys = d.evaluation_keys(envelopes, OC, GRID, ev, PROTOCOL, own)
    texts = {c: {k.text for k in ks} for c, ks in keys.items()}
    assert "nrrt_star~0.5[oracle_path@s4]" in texts[INF]  # its own envelope, in its own cell
    assert "nrrt_star~0.5[oracle_path@s4]" not in texts["eta=10 radius=shrinking goal=inf"]
    assert "nrrt_star~0.5[oracle_path@s1]" in texts[INF]  # the protocol's, everywhere


def _speedup(base: pd.DataFrame, plan: pd.DataFrame) -> dict:
    """Each instance's ratio of medians is constant here: the geometric mean is that ratio."""
    r = (base["iterations"].median() + 1) / (plan["iterations"].median() + 1)
    return {"iterations": {"speedup": r, "ci_low": r * 0.9, "ci_high": r * 1.1}}


def test_a_cells_own_envelope_is_read_against_rrt_the_protocols_and_its_path():
    table, members, _ = _selection()
    _, envelopes, own = by_cell(table, members)
    ev = table[table["regime"] == INF]
    rows = own_rows(ev, envelopes, own, _speedup)
    by = {(r["idea"]): r for r in rows}
    assert set(by) == {"path", "vertex"}
    assert by["path"]["over_rrt"]["iterations"]["speedup"] == pytest.approx(1001 / 51)
    assert by["path"]["vs_protocol"]["iterations"]["speedup"] == pytest.approx(401 / 51)
    assert "vs_path" not in by["path"] and by["vertex"]["vs_path"]["iterations"]["speedup"] == 1
    assert own_finding(rows, "optimal", 0.01, distinct={"protocol": ["protocol"]}) == []
    assert own_finding(rows, "optimal", 0.01, {INF: [INF]}) == own_finding(rows, "optimal", 0.01)
    said = own_finding(rows, "optimal", 0.01)[0]
    assert (
        "2 of 2 (cell, family) envelopes differ" in said and "2 of them save clearly more" in said
    )
    table_text = own_table(rows, "optimal")
    assert f"| {INF} | path | NRRT* mix 0.5 [oracle_path@s4] | 19.63x" in table_text
    assert own_table(rows, "optimal_any_angle") == "(not run)"


def test_the_selection_stage_plans_every_cell_with_its_own_settings(monkeypatch):
    """Stage ``oracle@0`` at the smoke scale (per_cell on), through the restricted view the
    stage gets: the protocol's jobs (every stop rule) first, then each regime cell's (the
    optimal ones), each with a planner setting the run has."""
    from vnrrt.config import REPO_ROOT, compose, restrict, stage_params
    from vnrrt.pipeline.sampling_ideas import Study, _study, part_settings

    cfg = restrict(compose(["scale=smoke"]), stage_params("oracle@0", REPO_ROOT / "dvc.yaml"))
    s = part_settings(cfg, "oracle")
    st = _study(s)
    monkeypatch.setattr(Study, "instances", lambda self: (["random"] * 4, [0, 2], [1, 3]))
    jobs = st.selection_jobs()
    cells = st.selection_cells()
    assert list(cells) == ["", INF] and cells[INF]["eta"] == float("inf")
    keys = d.selection_keys(st.oracle, s["planner"].tau)
    per = {c: [j for j in jobs if j.regime == c] for c in cells}
    trials = st.oracle.trials
    assert sum(j.count for j in per[""]) == len(keys) * 2 * 3 * trials
    assert sum(j.count for j in per[INF]) == len(keys) * 2 * 2 * trials
    assert {j.stop for j in per[INF]} == {"optimal", "optimal_any_angle"}
    assert [j.seq for j in jobs] == sorted(j.seq for j in jobs) and jobs[0].regime == ""
