"""The DVC pipeline end to end at smoke scale, in a scratch copy of the repository."""

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from tests.conftest import copy_pipeline
from vnrrt.config import DataConfig, LabelsConfig, compose, dump
from vnrrt.data.build import build_shard
from vnrrt.data.heatmaps import read_heatmaps
from vnrrt.data.manifest import verify_manifest
from vnrrt.data.shards import shard_file
from vnrrt.evaluation.evaluate import read_trials


def run(cmd: list[str], cwd: Path, **env_vars: str) -> str:
    env = dict(os.environ, PATH=f"{Path(sys.executable).parent}{os.pathsep}{os.environ['PATH']}")
    env.update(env_vars)
    proc = subprocess.run(cmd, cwd=cwd, env=env, capture_output=True, text=True, check=False)
    assert proc.returncode == 0, f"{' '.join(cmd)} failed:\n{proc.stdout}\n{proc.stderr}"
    return proc.stdout + proc.stderr


@pytest.fixture(scope="module")
def workdir(tmp_path_factory, repo):
    work = copy_pipeline(repo, tmp_path_factory.mktemp("pipeline"))
    run(["git", "init", "-q"], work)
    run(["dvc", "init", "-q"], work)
    shutil.copy(repo / ".dvc" / "config", work / ".dvc" / "config")
    (work / "params.yaml").write_text(dump(compose(["scale=smoke"])))
    return work


# The data stages only: training, prediction and evaluation have their own (slow) tests.
DATA_STAGES = ["manifest", "named_maps"]


def test_dvc_repro_smoke_builds_verified_deterministic_shards(workdir):
    run(["dvc", "repro", *DATA_STAGES], workdir)
    manifest = workdir / "data" / "manifest.json"
    assert len(verify_manifest(manifest)) == 2
    metrics = json.loads((workdir / "reports" / "metrics" / "data.json").read_text())
    assert metrics["instances"] == 2 * 4 * 144 and metrics["bytes_per_instance"] < 700
    assert (workdir / "reports" / "figures" / "named_maps.png").stat().st_size > 10_000
    direct = workdir / "direct.npz"
    build_shard(direct, 1, 0, 4, DataConfig(), LabelsConfig(), workers=1)
    assert direct.read_bytes() == shard_file(workdir / "data" / "shards", 1).read_bytes()
    assert "didn't change" in run(["dvc", "repro", *DATA_STAGES], workdir)


def test_an_interrupted_run_resumes_after_the_last_finished_shard(workdir):
    """DVC records each finished stage in dvc.lock; a run stopped after shard@0 resumes
    with shard@1 and does not redo shard@0."""
    (workdir / "params.yaml").write_text(dump(compose(["scale=smoke", "seed=1"])))
    run(["dvc", "repro", "shard@0"], workdir)  # the run that got this far, then stopped
    out = run(["dvc", "repro", *DATA_STAGES], workdir)
    assert "Running stage 'shard@1'" in out and "Running stage 'shard@0'" not in out
    assert not list((workdir / "data").rglob("*.tmp-*"))


def test_smoke_dvc_repro_end_to_end_writes_report_metrics_and_mlflow_runs(workdir):
    """Every stage at smoke scale: training, prediction, evaluation, report and MLflow."""
    from mlflow import MlflowClient

    env_uri = os.environ.pop("MLFLOW_TRACKING_URI", None)
    try:
        run(["dvc", "repro"], workdir)
    finally:
        if env_uri is not None:
            os.environ["MLFLOW_TRACKING_URI"] = env_uri
    report = (workdir / "reports" / "paper_comparison.md").read_text()
    assert "| vnrrt_star | ours | " in report and "| m_vnrrt_star@0.5 | ours | " in report
    assert "ok" in report.split("## Table 3")[1]  # our cells hold numbers and success counts
    metrics = json.loads((workdir / "reports" / "metrics" / "eval.json").read_text())
    assert metrics["optimal"]["rrt_star"]["random"]["success_rate"] > 0.5
    assert metrics["initial"]["vnrrt_star"]["map_3"]["time_median"] > 0
    client = MlflowClient(f"sqlite:///{workdir / 'mlflow.db'}")
    exp = client.get_experiment_by_name("vnrrt")
    runs = client.search_runs([exp.experiment_id])
    stages = sorted(r.data.tags.get("dvc_stage", "") for r in runs)
    assert stages.count("train_vertexnet") == 1 and stages.count("train_nrrtnet") == 1
    parents = [r for r in runs if r.data.tags.get("kind") == "evaluation"
               and "mlflow.parentRunId" not in r.data.tags]  # fmt: skip
    children = [r for r in runs if r.data.tags.get("mlflow.parentRunId") == parents[0].info.run_id]
    assert len(parents) == 1 and len(children) == 6
    assert all(c.data.metrics["optimal/random/success_rate"] >= 0 for c in children)


# Trial columns that depend on seeds and inputs only, not on timing or the machine's load.
DETERMINISTIC = ["planner", "tau", "map_set", "map", "trial", "stop", "success", "cost",
                 "iterations", "tree_size", "collision_checks", "reference_length",
                 "seq"]  # fmt: skip


def test_predict_and_trial_parts_as_multirun_jobs_write_the_stage_files(workdir, request):
    """After the end-to-end run: the predict@<k> and trials@<k> parts again, as Hydra
    multirun shard jobs (joblib; trials on the local SLURM cluster where it runs). They write
    the stages' files: heatmaps equal up to float16 rounding (threads differ), trials equal in
    every column but the timings given the same heatmaps; `dvc commit` makes `dvc repro`
    skip the stages."""
    heat, trials = workdir / "data" / "heatmaps", workdir / "reports" / "eval" / "trials"
    stage_bytes = {p.name: p.read_bytes() for p in sorted(heat.glob("part_*.npz"))}
    stage_heat = {name: read_heatmaps(heat / name) for name in stage_bytes}
    stage_trials = read_trials(trials, [0, 1])
    assert len(stage_heat) == 2
    shutil.rmtree(heat)
    shutil.rmtree(trials)
    env = {"VNRRT_CONF_DIR": str(workdir / "conf")}
    # the overrides of params.yaml (test_an_interrupted_run... wrote seed=1)
    job = [sys.executable, "-m", "vnrrt.multirun", "-m", "scale=smoke", "seed=1", "workers=1",
           "+part=0,1"]  # fmt: skip
    out = run([*job, "+stage=predict", "hydra/launcher=local"], workdir, **env)
    assert "differs from params.yaml" not in out
    for name, want in stage_heat.items():
        got = read_heatmaps(heat / name)
        np.testing.assert_array_equal(got["keys"], want["keys"])
        for net, maps in want["maps"].items():
            # equal up to float16 rounding: CPU threads (1 per joblib job) change sum orders
            np.testing.assert_allclose(got["maps"][net].astype(np.float32), maps, rtol=4e-3,
                                       atol=1e-4, err_msg=f"{name} {net}")  # fmt: skip
    for name, data in stage_bytes.items():  # the trials below run on the stage's heatmaps
        (heat / name).write_bytes(data)
    try:
        env["SLURM_CONF"] = request.getfixturevalue("slurm")
        launcher = ["hydra/launcher=slurm", "hydra.launcher.cpus_per_task=1",
                    "hydra.launcher.mem_gb=2", "hydra.launcher.timeout_min=10"]  # fmt: skip
    except pytest.skip.Exception:
        launcher = ["hydra/launcher=local"]
    run([*job, "+stage=trials", *launcher], workdir, **env)
    got = read_trials(trials, [0, 1])
    pd.testing.assert_frame_equal(got[DETERMINISTIC], stage_trials[DETERMINISTIC])

    run(["dvc", "commit", "-f", "predict", "trials"], workdir)
    out = run(["dvc", "repro", "evaluate"], workdir)
    for stage in ("predict@0", "predict@1", "trials@0", "trials@1"):
        assert f"Stage '{stage}' didn't change" in out
    assert "Running stage 'evaluate'" in out
