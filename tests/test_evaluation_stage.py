"""The trials, evaluate and report stages on tiny data with oracle heatmaps (no training
needed): trial parts and their merge, metrics, curves, report, figures and nested MLflow
runs."""

import copy
import json
import os
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from vnrrt.config import DataConfig, LabelsConfig, compose
from vnrrt.data.build import build_named_maps, build_shard
from vnrrt.data.heatmaps import part_file, write_heatmaps
from vnrrt.data.reader import Shard
from vnrrt.data.shards import shard_file
from vnrrt.evaluation.evaluate import read_trials, trials_file
from vnrrt.evaluation.stage import run_evaluate, run_report, run_trials_part

NETS = (("vertexnet", "vertex"), ("nrrtnet", "path"))
# Columns that depend on the seeds only (not on timing): equal whatever the split.
DETERMINISTIC = [
    "planner",
    "tau",
    "map_set",
    "map",
    "trial",
    "stop",
    "success",
    "cost",
    "iterations",
    "tree_size",
    "collision_checks",
    "reference_length",
    "seq",
]


def oracle(shard: Shard, i: int, target: str) -> np.ndarray:
    """A perfect network: probability 1 on the target cells, 0.02 elsewhere."""
    mask = shard.vertex_mask(i) if target == "vertex" else shard.path_mask(i)
    return np.where(mask, 1.0, 0.02)


@pytest.fixture(scope="module")
def cfg(tmp_path_factory, repo):
    tmp = tmp_path_factory.mktemp("eval")
    build_shard(shard_file(tmp / "shards", 0), 0, 0, 2, DataConfig(), LabelsConfig(), workers=1)
    build_named_maps(tmp / "named.npz", 200, LabelsConfig())
    shard, named = Shard(shard_file(tmp / "shards", 0)), Shard(tmp / "named.npz")
    test = shard.instances("test")[:3]
    named_maps = {
        net: np.stack([oracle(named, i, target) for i in range(5)]) for net, target in NETS
    }
    write_heatmaps(tmp / "heat_named.npz", np.stack([[-1] * 5, range(5)], axis=1), named_maps)
    for part, rows in enumerate((test[:1], test[1:])):  # two heatmap parts of 1 and 2
        maps = {net: np.stack([oracle(shard, i, target) for i in rows]) for net, target in NETS}
        write_heatmaps(part_file(tmp / "heat", part), np.stack([np.zeros_like(rows), rows], axis=1),
                       maps)  # fmt: skip
    over = [f"paths.shards={tmp / 'shards'}", f"paths.named_maps={tmp / 'named.npz'}",
            f"paths.heatmaps={tmp / 'heat'}", f"paths.named_heatmaps={tmp / 'heat_named.npz'}",
            f"paths.trials={tmp / 'eval/trials'}", "predict.parts=[0,1]", "eval.parts=[0,1,2]",
            f"paths.plots={tmp / 'plots'}", f"paths.metrics={tmp / 'metrics'}",
            f"paths.report={tmp / 'report.md'}", f"paths.figures={tmp / 'figures'}",
            f"paths.paper_tables={repo / 'reports/paper/tables.yaml'}",
            f"logger.uri=sqlite:///{tmp / 'mlflow.db'}",
            f"logger.artifact_location={(tmp / 'artifacts').as_uri()}",
            "scale=smoke", "scale.shards=[0]", "eval.named_initial=3", "eval.named_optimal=2",
            "eval.random_maps=3", "planner.max_seconds=5", "workers=1"]  # fmt: skip
    return compose(over)


def test_trial_parts_merge_into_the_protocol_table(cfg):
    sizes = [run_trials_part(cfg, k) for k in cfg.eval.parts]
    metrics = run_evaluate(cfg)
    trials = read_trials(cfg.paths.trials, cfg.eval.parts)
    n_configs = 3 + len({0.5, 0.9, 0.99, cfg.planner.tau})
    assert len(trials) == sum(sizes) == n_configs * (5 * (3 + 2 + 2) + 3 * (1 + 1 + 1))
    assert min(sizes) > 0.2 * max(sizes)  # round robin: parts of similar size
    strict = trials[trials["stop"] == "optimal_any_angle"]
    loose = trials[trials["stop"] == "optimal"]
    assert (strict["reference_length"].to_numpy() < loose["reference_length"].to_numpy()).all()
    assert set(trials["map_set"]) == {"map_1", "map_2", "map_3", "map_4", "map_5", "random"}
    assert trials["success"].mean() > 0.9
    on_disk = json.loads(Path(f"{cfg.paths.metrics}/eval.json").read_text())
    assert on_disk["optimal"]["vnrrt_star"]["map_3"]["success_rate"] == pytest.approx(
        metrics["optimal"]["vnrrt_star"]["map_3"]["success_rate"])  # fmt: skip
    curves = pd.read_csv(f"{cfg.paths.plots}/convergence.csv")
    assert {"planner", "map_set", "factor", "median_time"} <= set(curves.columns)


def test_report_stage_writes_report_figures_and_nested_mlflow_runs(cfg):
    import mlflow

    run_report(cfg)
    text = Path(cfg.paths.report).read_text()
    assert "Table 3" in text and "| vnrrt_star | ours |" in text
    assert "any-angle" in text
    for name in ("improvement_initial.png", "improvement_optimal.png", "convergence.png",
                 "improvement_optimal_any_angle.png"):  # fmt: skip
        assert os.path.getsize(f"{cfg.paths.figures}/{name}") > 5000
    mlflow.set_tracking_uri(cfg.logger.uri)
    runs = mlflow.search_runs(experiment_names=[cfg.logger.experiment])
    nested = runs["tags.mlflow.parentRunId"].notna()
    parent = runs[~nested]
    assert len(parent) == 1 and parent["tags.kind"].iloc[0] == "evaluation"
    children = runs[nested]
    assert set(children["tags.mlflow.parentRunId"]) == {parent["run_id"].iloc[0]}
    keys = {"rrt_star", "nrrt_star", "vnrrt_star"} | {
        f"m_vnrrt_star@{t:g}" for t in {0.5, 0.9, 0.99, cfg.planner.tau}}  # fmt: skip
    assert set(children["tags.planner"]) == keys
    assert children["metrics.optimal/random/success_rate"].notna().all()


def test_the_table_does_not_depend_on_the_split(cfg, tmp_path):
    """One part gives the same trials (all but the timings) as three parts merged."""
    split = read_trials(cfg.paths.trials, cfg.eval.parts)
    one = copy.deepcopy(cfg)
    one.eval.parts, one.paths.trials = [0], str(tmp_path / "one")
    run_trials_part(one, 0)
    whole = read_trials(one.paths.trials, [0])
    pd.testing.assert_frame_equal(whole[DETERMINISTIC], split[DETERMINISTIC])


def test_missing_or_foreign_parts_are_refused(cfg, tmp_path):
    with pytest.raises(FileNotFoundError, match="part_5.csv"):
        read_trials(cfg.paths.trials, [0, 5])
    with pytest.raises(ValueError, match="a part is missing, repeated or from another config"):
        read_trials(cfg.paths.trials, [0, 0, 1, 2])
    bad = copy.deepcopy(cfg)
    bad.eval.parts = [1, 2]
    with pytest.raises(Exception, match=r"eval.parts=\[1, 2\]"):
        run_trials_part(bad, 1)
    assert trials_file(tmp_path, 3).name == "part_3.csv"
