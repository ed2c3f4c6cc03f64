"""The sampling-ideas summary's per-cell rows
(:func:`vnrrt.studies.sampling_ideas.rows.cell_rows`) on a hand-made table: success, the
runs the time budget and the runs' cap cut, and the speed-up."""

import pandas as pd
import pytest

from vnrrt.studies.sampling_ideas.rows import cell_rows


def _rows(key: str, iterations: list[int], reasons: list[str], runs=None) -> list[dict]:
    runs = runs or reasons  # how each run itself stopped (its cap above the time budget)
    return [{"regime": "eta=10", "stop": "optimal", "key": key, "source": "", "instance": i,
             "trial": 0, "cluster": i, "iterations": it, "time_to_stop": it * 1e-5,
             "success": why == "solved", "stop_reason": why, "run_stop_reason": run,
             "heat_mass": float("nan"), "uniform_mass": float("nan")}
            for i, (it, why, run) in enumerate(zip(iterations, reasons, runs, strict=True))
            ]  # fmt: skip


def test_a_cell_row_counts_the_runs_cut_by_the_time_budget_and_by_the_cap():
    rrt = _rows("rrt_star", [100, 400, 900, 1600], ["solved", "max_seconds", "max_seconds",
                                                    "max_iterations"],
                ["solved", "max_seconds", "solved", "max_iterations"])  # fmt: skip
    nrrt = _rows("nrrt_star", [50, 100, 300, 400], ["solved"] * 4)
    got = {r["configuration"]: r for r in cell_rows(pd.DataFrame(rrt + nrrt), (200, 0.95))}
    assert got["rrt_star"]["cut_by_time"] == 2 and got["nrrt_star"]["cut_by_time"] == 0
    assert got["rrt_star"]["cut_by_cap"] == 1 and got["nrrt_star"]["cut_by_cap"] == 0
    assert got["rrt_star"]["success_rate"] == 0.25 and got["nrrt_star"]["success_rate"] == 1.0
    # iterations + 1 per instance: (101/51 * 401/101 * 901/301 * 1601/401) ** (1/4)
    want = ((101 / 51) * (401 / 101) * (901 / 301) * (1601 / 401)) ** 0.25
    assert got["nrrt_star"]["iterations"]["speedup"] == pytest.approx(want)
