"""Kept trial rows (vnrrt.evaluation.reuse): an ablation re-runs only the configurations whose
inputs changed; the others' rows come back byte for byte, timings included, renumbered to the
current protocol; a changed setting, heatmap, seed or code re-runs what it touches; a damaged
kept file runs again."""

import dataclasses
import logging

import numpy as np
import pytest

from tests.evaluation.test_trials import wall_instance
from vnrrt.evaluation import reuse, trials
from vnrrt.evaluation.keys import ConfigKey
from vnrrt.evaluation.protocol import trial_jobs
from vnrrt.evaluation.table import SEEDED_COLUMNS, write_table
from vnrrt.evaluation.trials import LIBRARY_SETTINGS, run_jobs
from vnrrt.planners import PlannerConfig

RRT, NRRT = ConfigKey("rrt_star"), ConfigKey("nrrt_star", source="path")
COUNTS = {("random", "initial"): 2, ("random", "optimal"): 1}
CONFIG = PlannerConfig(max_iterations=20000)


@pytest.fixture(scope="module")
def instances():
    return {i: wall_instance("random", i) for i in range(2)}


@pytest.fixture
def calls(monkeypatch):
    """The (key text, instance) of every job actually planned."""
    seen = []
    real = trials.run_job

    def counting(args, **kw):
        seen.append((args[0].key.text, args[0].instance))
        return real(args, **kw)

    monkeypatch.setattr(trials, "run_job", counting)
    return seen


def run(instances, keys, store, config=CONFIG, seed=0):
    jobs = trial_jobs([inst.kind for inst in instances.values()], keys, COUNTS)
    return run_jobs(jobs, instances, seed, 1, config, LIBRARY_SETTINGS, store)


def csv(table, tmp_path, name) -> bytes:
    write_table(table, tmp_path / name)
    return (tmp_path / name).read_bytes()


def mvn(tau):
    return ConfigKey("m_vnrrt_star", tau, "vertex")


def test_an_unchanged_run_reuses_every_row_byte_for_byte(instances, tmp_path, calls, caplog):
    first = run(instances, [RRT, NRRT, mvn(0.5)], tmp_path / "store")
    assert len(calls) == 3 * 2 * 2 and len(first) == 3 * 2 * 3
    calls.clear()
    with caplog.at_level(logging.INFO, logger="vnrrt.evaluation.trials"):
        again = run(instances, [RRT, NRRT, mvn(0.5)], tmp_path / "store")
    assert calls == [] and "reused 3 of 3 configurations" in caplog.text
    assert csv(again, tmp_path, "a.csv") == csv(first, tmp_path, "b.csv")


def test_a_tau_ablation_reruns_only_m_vnrrt_and_renumbers_the_rest(instances, tmp_path, calls):
    first = run(instances, [RRT, NRRT, mvn(0.5)], tmp_path / "store")
    calls.clear()
    ablation = run(instances, [RRT, NRRT, mvn(0.7)], tmp_path / "store")
    assert {k for k, _ in calls} == {"m_vnrrt_star@0.7"}
    same = first["key"] != "m_vnrrt_star@0.5"
    kept = ablation[ablation["key"] != "m_vnrrt_star@0.7"]
    assert csv(kept.reset_index(drop=True), tmp_path, "a.csv") == csv(
        first[same].reset_index(drop=True), tmp_path, "b.csv"
    )
    # a configuration added first moves every other row; the kept rows follow their jobs
    calls.clear()
    grown = run(instances, [ConfigKey("rrt_star", informed=True), RRT, NRRT], tmp_path / "store")
    assert {k for k, _ in calls} == {"rrt_star+informed"}
    fresh = run(instances, [ConfigKey("rrt_star", informed=True), RRT, NRRT], None)
    np.testing.assert_array_equal(grown["seq"], np.arange(len(grown)))
    assert grown[list(SEEDED_COLUMNS)].equals(fresh[list(SEEDED_COLUMNS)])


def test_planner_tau_and_taus_rerun_no_configuration_naming_its_tau(instances, tmp_path, calls):
    run(instances, [RRT, NRRT, mvn(0.5)], tmp_path / "store")
    calls.clear()
    ablation = CONFIG.replace(tau=0.7, taus=[0.3, 0.7])
    run(instances, [RRT, NRRT, mvn(0.5)], tmp_path / "store", config=ablation)
    assert calls == []  # M-VNRRT*'s key names its own tau: the config's is not read


def test_a_setting_every_configuration_uses_reruns_them_all(instances, tmp_path, calls):
    run(instances, [RRT, NRRT], tmp_path / "store")
    calls.clear()
    run(instances, [RRT, NRRT], tmp_path / "store", config=CONFIG.replace(eta=12.0))
    assert {k for k, _ in calls} == {RRT.text, NRRT.text} and len(calls) == 2 * 2 * 2
    calls.clear()
    run(instances, [RRT, NRRT], tmp_path / "store", seed=1)
    assert len(calls) == 2 * 2 * 2


def test_a_changed_heatmap_reruns_the_configurations_that_read_it(instances, tmp_path, calls):
    run(instances, [RRT, NRRT, mvn(0.5)], tmp_path / "store")
    calls.clear()
    inst = instances[1]
    heat = inst.heatmaps["path"].copy()
    heat[0, 0] = 0.5
    changed = {**instances, 1: dataclasses.replace(inst, heatmaps={**inst.heatmaps, "path": heat})}
    run(changed, [RRT, NRRT, mvn(0.5)], tmp_path / "store")
    assert {k for k, _ in calls} == {NRRT.text}


def test_changed_code_reruns_everything(instances, tmp_path, calls, monkeypatch):
    run(instances, [RRT], tmp_path / "store")
    calls.clear()
    monkeypatch.setattr(reuse, "code_digest", lambda: "another version")
    run(instances, [RRT], tmp_path / "store")
    assert len(calls) == 2 * 2


def test_a_damaged_kept_file_runs_again(instances, tmp_path, calls, caplog):
    first = run(instances, [RRT], tmp_path / "store")
    (kept,) = (tmp_path / "store").iterdir()
    kept.write_text(kept.read_text()[:-40])  # truncated mid-row
    calls.clear()
    with caplog.at_level(logging.WARNING, logger="vnrrt.evaluation.reuse"):
        again = run(instances, [RRT], tmp_path / "store")
    assert len(calls) == 2 * 2 and str(kept) in caplog.text
    assert again[list(SEEDED_COLUMNS)].equals(first[list(SEEDED_COLUMNS)])


def test_the_digest_tells_values_types_and_shapes_apart():
    a = np.zeros((2, 3), np.float32)
    assert reuse.digest(a) != reuse.digest(a.reshape(3, 2))
    assert reuse.digest(a) != reuse.digest(a.astype(np.float64))
    assert reuse.digest(1) != reuse.digest(1.0) != reuse.digest(True)
    assert reuse.digest({"a": 1}) == reuse.digest({"a": 1}) != reuse.digest({"a": 2})
    assert reuse.digest(0.1 + 0.2) != reuse.digest(0.3)


def test_a_configurations_jobs_keep_their_parts_when_others_come_or_go():
    """Parts by what a job runs (protocol.part_of), not by its place in the list: an ablation
    that adds M-VNRRT* at tau 0.7 leaves every other configuration's jobs in their parts (so
    their kept rows fit again); the parts still partition the jobs, in similar sizes."""
    from vnrrt.evaluation.protocol import part_jobs

    kinds = ["random"] * 40
    counts = {("random", "initial"): 1, ("random", "optimal"): 2}
    before = trial_jobs(kinds, [RRT, NRRT, mvn(0.5), mvn(0.9)], counts)
    after = trial_jobs(kinds, [RRT, NRRT, mvn(0.5), mvn(0.7), mvn(0.9)], counts)

    def part(jobs, k):
        return {(j.key.text, j.instance, j.stop, j.first) for j in part_jobs(jobs, k, 3)}

    for k in range(3):
        assert {x for x in part(after, k) if x[0] != "m_vnrrt_star@0.7"} == part(before, k)
    sizes = [len(part(after, k)) for k in range(3)]
    assert sum(sizes) == len(after) and min(sizes) > 0.7 * max(sizes)
