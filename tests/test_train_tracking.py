"""MLflow tracking: the default SQLite store, artifact roots that follow the repository, tags,
and what a training run records (an MLflow Model that predicts what the checkpoint does)."""

import os
import shutil
from pathlib import Path

import numpy as np
from mlflow import MlflowClient

from tests.train_helpers import small_cfg
from vnrrt import tracking
from vnrrt.training.stage import run_train


def test_default_store_is_sqlite_in_the_repository(tmp_path, monkeypatch):
    for var in ("MLFLOW_TRACKING_URI", "DVC_ROOT"):
        monkeypatch.delenv(var, raising=False)
    (tmp_path / "dvc.yaml").write_text("stages: {}\n")
    inside = tmp_path / "a" / "b"
    inside.mkdir(parents=True)
    monkeypatch.chdir(inside)
    uri = tracking.tracking_uri()
    assert uri == f"sqlite:///{tmp_path}/mlflow.db"
    assert tracking.artifact_root(uri) == (tmp_path / "mlartifacts").as_uri()
    monkeypatch.setenv("DVC_ROOT", str(inside))  # set by `dvc repro` for its stages
    assert tracking.tracking_uri() == f"sqlite:///{inside}/mlflow.db"
    monkeypatch.setenv("MLFLOW_TRACKING_URI", "sqlite:////elsewhere.db")
    assert tracking.tracking_uri() == "sqlite:////elsewhere.db"
    assert tracking.tracking_uri("sqlite:////configured.db") == "sqlite:////configured.db"
    assert tracking.configure("sqlite:////x.db") == "sqlite:////x.db"
    assert os.environ["MLFLOW_TRACKING_URI"] == "sqlite:////x.db"
    assert os.environ["MLFLOW_DISABLE_TELEMETRY"] == "true"  # no calls home from stages


def test_a_copied_repository_writes_its_artifacts_inside_the_copy(tmp_path):
    import mlflow

    original = tmp_path / "original"
    original.mkdir()
    uri = f"sqlite:///{original / 'mlflow.db'}"
    exp = tracking.experiment_id("vnrrt-smoke", uri)
    mlflow.set_tracking_uri(uri)
    with mlflow.start_run(experiment_id=exp) as run:
        pass
    assert run.info.artifact_uri.startswith((original / "mlartifacts").as_uri())
    copy = tmp_path / "copy"
    shutil.copytree(original, copy)
    copy_uri = f"sqlite:///{copy / 'mlflow.db'}"
    exp = tracking.experiment_id("vnrrt-smoke", copy_uri)
    mlflow.set_tracking_uri(copy_uri)
    with mlflow.start_run(experiment_id=exp) as run:
        mlflow.log_text("hello", "note.txt")
    assert run.info.artifact_uri.startswith((copy / "mlartifacts").as_uri())
    assert list((copy / "mlartifacts").rglob("note.txt"))
    assert not list(original.rglob("note.txt"))


def test_git_commit_is_read_from_the_git_files(tmp_path):
    git = tmp_path / ".git"
    (git / "refs" / "heads").mkdir(parents=True)
    (git / "HEAD").write_text("ref: refs/heads/main\n")
    assert tracking.git_commit(tmp_path) == "unknown"  # no such ref yet
    (git / "packed-refs").write_text("# pack-refs\n" + "a" * 40 + " refs/heads/main\n")
    assert tracking.git_commit(tmp_path) == "a" * 40
    (git / "refs" / "heads" / "main").write_text("b" * 40 + "\n")
    assert tracking.git_commit(tmp_path) == "b" * 40
    (git / "HEAD").write_text("c" * 40 + "\n")  # detached
    assert tracking.git_commit(tmp_path) == "c" * 40
    assert tracking.git_commit(tmp_path / "nothing") == "unknown"


def test_params_are_flat_scalars():
    flat = tracking.flat_params({"a": {"b": [1, 2], "c": None, "d": {"e": 0.5}}})
    assert flat == {"a.b": "1,2", "a.c": "null", "a.d.e": 0.5}


def test_a_training_run_is_recorded_in_mlflow(small_data, tmp_path, monkeypatch):
    import mlflow.pytorch

    from vnrrt.predict import heatmap

    monkeypatch.setenv("DVC_STAGE", "train@vertexnet")
    monkeypatch.setenv("DVC_EXP_NAME", "tidy-exp")
    cfg = small_cfg(
        small_data,
        tmp_path,
        "logger.enabled=true",
        "trainer.max_epochs=2",
        "trainer.limit_train_batches=2",
        "trainer.limit_val_batches=1",
        "train.module.scheduler.pct_start=0.5",
    )
    metrics = run_train(cfg, "vertexnet")
    client = MlflowClient(f"sqlite:///{tmp_path}/mlflow.db")
    (run,) = client.search_runs([client.get_experiment_by_name("vnrrt-smoke").experiment_id])
    assert run.info.run_name == "vertexnet smoke" and metrics["mlflow_run_id"] == run.info.run_id
    tags = run.data.tags
    assert tags["dvc_stage"] == "train@vertexnet" and tags["dvc_experiment"] == "tidy-exp"
    assert tags["kind"] == "vertexnet" and tags["scale"] == "smoke"
    assert tags["checkpoint_sha256"] == metrics["checkpoint_sha256"]
    assert tags["git_commit"] == tracking.git_commit(Path(__file__).resolve().parents[1])
    params = run.data.params
    assert params["model.net.encoder"] == "resnet18" and params["data.size"] == "64"
    assert (
        params["networks.vertexnet.target"] == "vertex" and params["planner.taus"] == "0.5,0.9,0.99"
    )
    assert params["net_info.encoder_frozen"] == "False" and params["net_info.weights"] == "none"
    assert len(client.get_metric_history(run.info.run_id, "val/loss")) == 2  # per epoch
    assert "test/vertex_recall" in run.data.metrics and "train/loss_epoch" in run.data.metrics
    listed = {
        a.path for folder in ("", "figures") for a in client.list_artifacts(run.info.run_id, folder)
    }
    assert {"config.yaml", "figures/val_epoch_000.png", "figures/val_epoch_001.png"} <= listed
    assert run.info.artifact_uri.startswith((tmp_path / "mlartifacts").as_uri())
    # The network as an MLflow Model: loadable by URI, registered, same heatmap as the checkpoint.
    mlflow.set_tracking_uri(f"sqlite:///{tmp_path}/mlflow.db")
    model = mlflow.pytorch.load_model(f"runs:/{run.info.run_id}/model")
    assert client.get_registered_model("vnrrt-vertexnet").name == "vnrrt-vertexnet"
    from vnrrt.data.reader import Shard

    shard = Shard(small_data / "shards" / "shard_0.npz")
    inst = shard.instance(0)
    grid = shard.grid(inst["map_index"])
    from_ckpt = heatmap(tmp_path / "models" / "vertexnet.ckpt", grid, inst["start"], inst["goal"])
    from vnrrt.model.checkpoint import load_network
    from vnrrt.predict.api import Model, load_model

    from_mlflow = heatmap(Model(model.eval(), {}), grid, inst["start"], inst["goal"])
    np.testing.assert_allclose(from_mlflow, from_ckpt, atol=1e-6)
    # ... and by URI through vnrrt.predict, with the rendering the network was trained with
    monkeypatch.setenv("MLFLOW_TRACKING_URI", f"sqlite:///{tmp_path}/mlflow.db")
    for uri in (f"runs:/{run.info.run_id}/model", "models:/vnrrt-vertexnet/1"):
        loaded = load_model(uri)
        assert loaded.render == load_network(tmp_path / "models" / "vertexnet.ckpt")[1]["render"]
        np.testing.assert_allclose(
            heatmap(uri, grid, inst["start"], inst["goal"]), from_ckpt, atol=1e-6
        )
    assert not (tmp_path / "models" / "checkpoints" / "vertexnet").exists()  # cleaned up
