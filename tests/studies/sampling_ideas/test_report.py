"""The sampling-ideas report's per-cell readings, on hand-made summaries: which envelope wins
in which regime cell (an interval containing 1 is never a win) and which cells have runs
stopped by the budget."""

from vnrrt.studies.sampling_ideas.findings import _winner_finding, cells_by_winner
from vnrrt.studies.sampling_ideas.report import budget_table, censored_cells

CELLS = ["protocol", "eta=10", "eta=40", "eta=inf"]


def _ci(speedup: float, low: float, high: float) -> dict:
    return {"speedup": speedup, "ci_low": low, "ci_high": high}


def _summary(vertex_vs_path: dict, success: dict) -> dict:
    envelopes = [
        {"regime": c, "stop": "optimal", "idea": "vertex", "against": "path", "iterations": v}
        for c, v in vertex_vs_path.items()
    ]
    cells = [
        {"regime": c, "stop": "optimal", "configuration": k, "success_rate": rate}
        for (c, k), rate in success.items()
    ]
    return {"cell_names": CELLS, "envelopes": envelopes, "cells": cells}


def test_each_cell_goes_to_the_envelope_whose_interval_excludes_one():
    ratios = {
        "protocol": _ci(0.3, 0.2, 0.5),  # vertex needs more: path wins
        "eta=10": _ci(1.0, 0.5, 1.0),  # touches 1: no win
        "eta=40": _ci(2.0, 1.01, 3.0),  # vertex wins
        "eta=inf": _ci(1.2, 0.9, 1.6),  # contains 1
    }
    won = cells_by_winner(_summary(ratios, {}), "optimal")
    assert won == {"path": ["protocol"], "vertex": ["eta=40"], "unclear": ["eta=10", "eta=inf"]}
    said = _winner_finding(_summary(ratios, {}), "optimal", 0.01)[0]
    assert "in 1 of 4 cells (protocol)" in said and "vertex envelope in 1 (eta=40)" in said
    assert "no clear difference in 2" in said
    assert _winner_finding(_summary(ratios, {}), "optimal_any_angle", 0.01) == []


def test_only_cells_with_runs_stopped_by_the_budget_are_listed():
    success = {
        ("protocol", "rrt_star"): 1.0,
        ("protocol", "vnrrt_star"): 1.0,
        ("eta=10", "rrt_star"): 0.9,
        ("eta=10", "nrrt_star"): 0.75,
        ("eta=inf", "rrt_star"): 1.0,
        ("eta=inf", "vnrrt_star"): 0.5,
    }
    summary = _summary({}, success)
    for row in summary["cells"]:  # 3 runs of one configuration over the time budget, 1 capped
        hit = (row["regime"], row["configuration"]) == ("eta=10", "nrrt_star")
        row["cut_by_time"], row["cut_by_cap"] = (3, 1) if hit else (0, 0)
    got = censored_cells(summary, "optimal")
    assert got == [("eta=10", 0.9, 0.75, "nrrt_star", 3, 1),
                   ("eta=inf", 1.0, 0.5, "vnrrt_star", 0, 0)]  # fmt: skip
    table = budget_table(summary, "optimal")
    assert "| eta=10 | 90.0% | 75.0% | NRRT* | 3 | 1 |" in table and "protocol" not in table
    assert "(3 runs over every" in table and "(the last column, 1 in all)" in table
    assert "cap is 1 times it" in table  # a summary without the setting: its runs stopped there
    assert "| eta=inf | 100.0% | 50.0% | VNRRT* | 0 | 0 |" in table
    for row in summary["cells"]:  # a summary written before the cap: its time budget was it
        del row["cut_by_cap"]
    assert censored_cells(summary, "optimal")[0][4:] == (3, 3)
    clean = {k: 1.0 for k in success}
    assert budget_table(_summary({}, clean), "optimal").startswith("Every run")
