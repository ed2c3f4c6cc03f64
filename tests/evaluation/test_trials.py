"""Evaluation trials: the table schema, paired seeds, determinism across workers, failures as
rows, timings that exclude building the sampler, and the time budget applied after the run."""

import dataclasses
import time

import numpy as np
import pytest

from vnrrt.data.heatmaps import HeatmapError
from vnrrt.data.instances import EvalInstance
from vnrrt.evaluation import sampling as sampling_module
from vnrrt.evaluation.keys import ConfigKey
from vnrrt.evaluation.protocol import trial_seed
from vnrrt.evaluation.table import COLUMNS, CONVERGENCE_COLUMNS, solved
from vnrrt.evaluation.trials import LIBRARY_SETTINGS, run_trials, time_reading
from vnrrt.planners import Milestone, PlannerConfig, plan
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


def test_the_time_budget_applies_after_the_run_and_spares_the_iterations():
    """A run capped far above its time budget: the time readings see it stopped at the
    budget, the iterations are those of a run that no time budget stopped (same seeds)."""
    counts, budget = {("named", "optimal"): 3}, 1e-5  # 10 us: every run here takes longer
    free = run_trials([wall_instance()], SPECS[:1], counts, config=PlannerConfig(), workers=1)
    capped = dataclasses.replace(LIBRARY_SETTINGS, cap_factor=30.0 / budget)
    tight = run_trials([wall_instance()], SPECS[:1], counts, workers=1, heat=capped,
                       config=PlannerConfig(max_seconds=budget))  # fmt: skip
    assert tight["iterations"].equals(free["iterations"]) and tight["cost"].equals(free["cost"])
    assert (tight["run_stop_reason"] == "solved").all() and solved(tight, "iterations").all()
    assert (tight["stop_reason"] == "max_seconds").all() and not solved(tight, "time").any()
    assert (tight["time_to_stop"] == budget).all()
    assert tight[list(CONVERGENCE_COLUMNS)].isna().all().all()
    assert (free["run_stop_reason"] == free["stop_reason"]).all()


def test_time_reading_cuts_a_run_at_the_budget():
    r = plan(wall_instance().grid, (5.5, 50.5), (55.5, 50.5), stop="optimal",
             reference_length=60.0, milestones=(200.0, 61.0), seed=1)  # fmt: skip
    slow = dataclasses.replace(
        r,
        time_to_first=0.5,
        time_to_stop=2.0,
        milestones=(Milestone(200.0, 0.4, 3), Milestone(61.0, 1.5, 9)),
    )
    got = time_reading(slow, 1.0)
    assert got["success"] is False and got["stop_reason"] == "max_seconds"
    assert got["time_to_first"] == 0.5 and got["time_to_stop"] == 1.0
    assert got["convergence"][0] == 0.4 and np.isnan(got["convergence"][1])
    assert np.isnan(time_reading(slow, 0.3)["time_to_first"])
    within = time_reading(slow, 2.0)
    assert within["success"] == r.success and within["stop_reason"] == r.stop_reason
    assert within["time_to_stop"] == 2.0 and within["convergence"] == (0.4, 1.5)
