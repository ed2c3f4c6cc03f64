"""The evaluate and report stages on tiny data with oracle heatmaps (no training needed):
trial table, metrics, curves, report, figures and nested MLflow runs."""

import json
import os
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from vnrrt.config import DataConfig, LabelsConfig, compose
from vnrrt.data.build import build_named_maps, build_shard
from vnrrt.data.heatmaps import write_heatmaps
from vnrrt.data.reader import Shard
from vnrrt.data.shards import shard_file
from vnrrt.evaluation.stage import run_evaluate, run_report


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
    for net, target in (("vertexnet", "vertex"), ("nrrtnet", "path")):
        write_heatmaps(tmp / "heat" / f"{net}.npz",
                       np.stack([oracle(named, i, target) for i in range(5)]),
                       np.stack([oracle(shard, i, target) for i in test]),
                       np.stack([np.zeros_like(test), test], axis=1), network=net)  # fmt: skip
    over = [f"paths.shards={tmp / 'shards'}", f"paths.named_maps={tmp / 'named.npz'}",
            f"paths.heatmaps={tmp / 'heat'}", f"paths.trials={tmp / 'eval/trials.csv'}",
            f"paths.plots={tmp / 'plots'}", f"paths.metrics={tmp / 'metrics'}",
            f"paths.report={tmp / 'report.md'}", f"paths.figures={tmp / 'figures'}",
            f"paths.paper_tables={repo / 'reports/paper/tables.yaml'}",
            f"logger.uri=sqlite:///{tmp / 'mlflow.db'}",
            f"logger.artifact_location={(tmp / 'artifacts').as_uri()}",
            "scale=smoke", "scale.shards=[0]", "eval.named_initial=3", "eval.named_optimal=2",
            "eval.random_maps=3", "planner.max_seconds=5", "workers=1"]  # fmt: skip
    return compose(over)


def test_evaluate_writes_trials_metrics_and_curves(cfg):
    metrics = run_evaluate(cfg)
    trials = pd.read_csv(cfg.paths.trials)
    n_configs = 3 + len({0.5, 0.9, 0.99, cfg.planner.tau})
    assert len(trials) == n_configs * (5 * (3 + 2 + 2) + 3 * (1 + 1 + 1))
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
