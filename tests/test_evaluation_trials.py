"""Evaluation trials: table shape, determinism across workers, failures recorded as rows."""

import numpy as np
import pytest

from vnrrt.evaluation.report import TRIAL_COLUMNS
from vnrrt.evaluation.trials import EvalInstance, PlannerSpec, run_trials, trial_seed
from vnrrt.planners import PlannerConfig
from vnrrt.search import astar


def wall_instance(map_set="map_1") -> EvalInstance:
    grid = np.zeros((60, 60), np.uint8)
    grid[10:60, 30] = 1
    path, length = astar(grid, (5, 50), (55, 50))
    heat = np.zeros((60, 60))
    heat[path[:, 1], path[:, 0]] = 1.0  # an oracle "path network"
    return EvalInstance(map_set, map_set, grid, (5.5, 50.5), (55.5, 50.5), length,
                        {"path": heat, "vertex": heat})  # fmt: skip


SPECS = [PlannerSpec("rrt_star"), PlannerSpec("nrrt_star", heatmap="path"),
         PlannerSpec("m_vnrrt_star", 0.5, "vertex")]  # fmt: skip


def test_trial_table_has_a_row_per_trial_and_valid_values():
    trials = {("named", "initial"): 3, ("named", "optimal"): 2, ("random", "initial"): 1}
    table = run_trials([wall_instance(), wall_instance("random")], SPECS, trials, workers=1)
    assert list(table.columns[: len(TRIAL_COLUMNS)]) == list(TRIAL_COLUMNS)
    assert len(table) == 3 * (3 + 2) + 3 * 1
    ok = table[table["success"]]
    assert len(ok) == len(table)
    assert np.all(ok["cost"] >= np.hypot(50, 0) - 1e-9)
    opt = ok[ok["stop"] == "optimal"]
    assert np.all(opt["cost"] <= 1.01 * opt["reference_length"] + 1e-9)
    assert set(table["tau"].dropna()) == {0.5}


def test_trials_are_deterministic_and_worker_independent():
    trials = {("named", "initial"): 2}
    a = run_trials([wall_instance()], SPECS, trials, seed=3, workers=1)
    b = run_trials([wall_instance()], SPECS, trials, seed=3, workers=2)
    cols = ["planner", "trial", "cost", "iterations", "tree_size", "collision_checks"]
    assert a[cols].equals(b[cols])
    assert trial_seed(0, 1, SPECS[0], "initial", 0) != trial_seed(0, 1, SPECS[0], "initial", 1)


def test_a_budget_hit_is_a_failed_row_not_a_crash():
    table = run_trials([wall_instance()], SPECS[:1], {("named", "optimal"): 2},
                       config=PlannerConfig(max_iterations=5))  # fmt: skip
    assert len(table) == 2 and not table["success"].any()
    assert set(table["stop_reason"]) == {"max_iterations"}


def test_missing_heatmap_is_a_clear_error():
    inst = wall_instance()
    bare = EvalInstance(inst.map_set, inst.map, inst.grid, inst.start, inst.goal, 1.0)
    with pytest.raises(KeyError, match="no 'path' heatmap"):
        run_trials([bare], SPECS, {("named", "initial"): 1})


def test_optimal_runs_record_monotone_convergence_times():
    from vnrrt.evaluation.trials import CONVERGENCE_FACTORS, convergence_column

    table = run_trials([wall_instance()], SPECS[:2], {("named", "optimal"): 2})
    cols = [convergence_column(f) for f in CONVERGENCE_FACTORS]
    times = table[[*cols, "time_to_stop"]].to_numpy()
    assert np.all(np.isfinite(times))
    assert np.all(np.diff(times, axis=1) >= 0)  # looser bounds are reached first
    assert np.all(table["time_to_first"] <= times[:, 0])
