"""Evaluation trials: the table schema, paired seeds, determinism across workers, failures as
rows, and timings that exclude building the sampler."""

import dataclasses
import time

import numpy as np
import pytest

from vnrrt.data.heatmaps import HeatmapError
from vnrrt.data.instances import EvalInstance
from vnrrt.evaluation import sampling as sampling_module
from vnrrt.evaluation.keys import ConfigKey
from vnrrt.evaluation.protocol import trial_seed
from vnrrt.evaluation.table import COLUMNS, CONVERGENCE_COLUMNS
from vnrrt.evaluation.trials import run_trials
from vnrrt.planners import PlannerConfig, plan
from vnrrt.planners import planner as planner_api
from vnrrt.search import any_angle_path, astar, path_vertices


def wall_instance(map_set="map_1", index=0) -> EvalInstance:
    grid = np.zeros((60, 60), np.uint8)
    grid[10:60, 30] = 1
    path, length = astar(grid, (5, 50), (55, 50))
    exact_path, exact = any_angle_path(grid, (5.5, 50.5), (55.5, 50.5))
    heat = np.zeros((60, 60), np.float32)
    heat[path[:, 1], path[:, 0]] = 1.0  # an oracle "path network"
    return EvalInstance(
        index,
        (-1, index),
        map_set,
        map_set,
        7,
        grid,
        (5, 50),
        (55, 50),
        length,
        exact,
        exact,
        path,
        path_vertices(path),
        exact_path,
        {"path": heat, "vertex": heat},
    )


SPECS = [
    ConfigKey("rrt_star"),
    ConfigKey("nrrt_star", source="path"),
    ConfigKey("m_vnrrt_star", 0.5, "vertex"),
]


def test_trial_table_has_a_row_per_trial_and_valid_values():
    counts = {
        ("named", "initial"): 3,
        ("named", "optimal"): 2,
        ("named", "optimal_any_angle"): 2,
        ("random", "initial"): 1,
    }
    table = run_trials([wall_instance(), wall_instance("random", 1)], SPECS, counts, workers=1)
    assert list(table.columns) == list(COLUMNS)
    assert len(table) == 3 * (3 + 2 + 2) + 3 * 1
    assert table["success"].all() and (table["cluster"] == 7).all()
    assert np.all(table["cost"] >= np.hypot(50, 0) - 1e-9)
    for stop, ref in (("optimal", "astar_length"), ("optimal_any_angle", "exact_length")):
        sub = table[table["stop"] == stop]
        assert np.allclose(sub["reference_length"], getattr(wall_instance(), ref))
        assert np.all(sub["cost"] <= 1.01 * sub["reference_length"] + 1e-9)
    assert set(table["tau"].dropna()) == {0.5}
    assert set(table["key"]) == {"rrt_star", "nrrt_star", "m_vnrrt_star@0.5"}
    assert (table.loc[table["planner"] == "rrt_star", "source"] == "").all()


def test_seeds_are_paired_across_configurations():
    table = run_trials([wall_instance()], SPECS, {("named", "initial"): 3}, seed=5, workers=1)
    seeds = table.pivot(index="trial", columns="key", values="seed")
    assert (seeds.nunique(axis=1) == 1).all()  # every configuration: the same seed per trial
    assert seeds.iloc[:, 0].nunique() == 3
    assert trial_seed(0, 1, "initial", 0) != trial_seed(0, 1, "optimal", 0)
    assert trial_seed(0, 1, "initial", 0) != trial_seed(0, 2, "initial", 0)


def test_trials_are_deterministic_and_worker_independent():
    counts = {("named", "initial"): 2}
    a = run_trials([wall_instance()], SPECS, counts, seed=3, workers=1)
    b = run_trials([wall_instance()], SPECS, counts, seed=3, workers=2)
    cols = ["key", "trial", "seed", "cost", "iterations", "tree_size", "collision_checks"]
    assert a[cols].equals(b[cols])


def test_a_budget_hit_is_a_failed_row_not_a_crash():
    table = run_trials(
        [wall_instance()],
        SPECS[:1],
        {("named", "optimal"): 2},
        config=PlannerConfig(max_iterations=5),
    )
    assert len(table) == 2 and not table["success"].any()
    assert set(table["stop_reason"]) == {"max_iterations"}


def test_missing_heatmap_is_a_clear_error():
    bare = dataclasses.replace(wall_instance(), heatmaps={})
    with pytest.raises(HeatmapError, match="no 'path' heatmap"):
        run_trials([bare], SPECS, {("named", "initial"): 1})


def test_optimal_runs_record_monotone_convergence_times():
    table = run_trials([wall_instance()], SPECS[:2], {("named", "optimal"): 2})
    times = table[[*CONVERGENCE_COLUMNS, "time_to_stop"]].to_numpy()
    assert np.all(np.isfinite(times))
    assert np.all(np.diff(times, axis=1) >= 0)  # looser bounds are reached first
    assert np.all(table["time_to_first"] <= times[:, 0])


SLOW = 0.3  # seconds: a deliberately slow sampler build


def slow(make):
    def build(*args, **kwargs):
        time.sleep(SLOW)
        return make(*args, **kwargs)

    return build


def test_planning_time_excludes_building_the_sampler(monkeypatch):
    """A sampler build that takes 0.3 s shows up as setup time, never in the planning time:
    in plan() and in the evaluation's trials."""
    inst = wall_instance()
    monkeypatch.setattr(planner_api, "make_sampler", slow(planner_api.make_sampler))
    r = plan(inst.grid, inst.start, inst.goal, "nrrt_star", heatmap=inst.heatmaps["path"])
    assert r.setup_time >= SLOW and r.time_to_stop < SLOW and r.success
    monkeypatch.setattr(sampling_module, "make_sampler", slow(sampling_module.make_sampler))
    table = run_trials([inst], SPECS[1:2], {("named", "initial"): 3}, workers=1)
    assert (table["setup_time"] >= SLOW).all() and (table["time_to_stop"] < SLOW).all()
