"""2-process DDP training on CPU (gloo; in the default run, so CI runs it), and, slow, the
train + predict stages under DVC (test_pipeline's end-to-end smoke run covers them too)."""

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest
from mlflow import MlflowClient

from tests.conftest import copy_dvc_files, copy_pipeline
from tests.train_helpers import QUICK, SMALL, paths
from vnrrt.config import compose, dump
from vnrrt.data.heatmaps import read_parts
from vnrrt.model.checkpoint import load_network

REPO = Path(__file__).resolve().parents[2]


def run(cmd: list[str], cwd: Path) -> str:
    env = dict(os.environ, PATH=f"{Path(sys.executable).parent}{os.pathsep}{os.environ['PATH']}")
    env.pop("MLFLOW_TRACKING_URI", None)
    proc = subprocess.run(cmd, cwd=cwd, env=env, capture_output=True, text=True, check=False)
    assert proc.returncode == 0, f"{' '.join(cmd)} failed:\n{proc.stdout}\n{proc.stderr}"
    return proc.stdout + proc.stderr


@pytest.mark.slow
def test_ddp_trains_on_two_cpu_processes(small_data, tmp_path):
    cfg = compose([*SMALL, *paths(small_data, tmp_path), *QUICK, "trainer=ddp",
                   "trainer.accelerator=cpu", "trainer.devices=2"])  # fmt: skip
    params = tmp_path / "params.yaml"
    params.write_text(dump(cfg))
    out = run([sys.executable, "stages/train.py", "--network", "vertexnet", "--params",
               str(params)], REPO)  # fmt: skip
    assert "MEMBER: 2/2" in out and "gloo" in out
    metrics = json.loads((tmp_path / "metrics" / "train_vertexnet.json").read_text())
    assert metrics["steps"] == 2 and metrics["train_images"] == 2 * 4 * 2  # 2 processes
    load_network(tmp_path / "models" / "vertexnet.ckpt", "vertexnet")
    client = MlflowClient(f"sqlite:///{tmp_path / 'mlflow.db'}")
    runs = client.search_runs([client.get_experiment_by_name("vnrrt-smoke").experiment_id])
    assert len(runs) == 1  # rank 0 only


@pytest.mark.slow
def test_dvc_repro_trains_both_networks_and_predicts(tmp_path):
    copy_pipeline(REPO, tmp_path)
    run(["git", "init", "-q"], tmp_path)
    run(["dvc", "init", "-q"], tmp_path)
    copy_dvc_files(REPO, tmp_path)
    (tmp_path / "params.yaml").write_text(dump(compose(["scale=smoke"])))
    run(["dvc", "repro", "predict_metrics"], tmp_path)
    heat = read_parts(tmp_path / "data/smoke/heatmaps", [0, 1])
    for name, kind in (("vertexnet", "vertex"), ("nrrtnet", "path")):
        _, record = load_network(tmp_path / "models/smoke" / f"{name}.ckpt", name)
        assert record["target"]["kind"] == kind
        assert heat["maps"][name].shape == (5 + 8, 200, 200)
    client = MlflowClient(f"sqlite:///{tmp_path / 'mlflow.db'}")  # <repo>/mlflow.db
    runs = client.search_runs([client.get_experiment_by_name("vnrrt-smoke").experiment_id])
    assert sorted(r.data.tags["dvc_stage"] for r in runs) == ["train@nrrtnet", "train@vertexnet"]
    assert "didn't change" in run(["dvc", "repro", "predict_metrics"], tmp_path)
