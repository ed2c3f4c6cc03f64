"""MLflow tracking: the default SQLite store, tags, and what a training run records."""

from pathlib import Path

from mlflow import MlflowClient

from tests.train_helpers import small_cfg
from vnrrt import tracking
from vnrrt.train import train


def test_default_store_is_sqlite_in_the_repository(tmp_path, monkeypatch):
    for var in ("MLFLOW_TRACKING_URI", "DVC_ROOT"):
        monkeypatch.delenv(var, raising=False)
    (tmp_path / "dvc.yaml").write_text("stages: {}\n")
    inside = tmp_path / "a" / "b"
    inside.mkdir(parents=True)
    monkeypatch.chdir(inside)
    assert tracking.tracking_uri() == f"sqlite:///{tmp_path}/mlflow.db"
    assert tracking.artifact_location() == (tmp_path / "mlartifacts").as_uri()
    monkeypatch.setenv("DVC_ROOT", str(inside))  # set by `dvc repro` for its stages
    assert tracking.tracking_uri() == f"sqlite:///{inside}/mlflow.db"
    monkeypatch.setenv("MLFLOW_TRACKING_URI", "sqlite:////elsewhere.db")
    assert tracking.tracking_uri() == "sqlite:////elsewhere.db"
    assert tracking.tracking_uri("sqlite:////configured.db") == "sqlite:////configured.db"
    assert tracking.configure("sqlite:////x.db") == "sqlite:////x.db"
    import os

    assert os.environ["MLFLOW_TRACKING_URI"] == "sqlite:////x.db"


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


def test_a_training_run_is_recorded_in_mlflow(small_data, tmp_path, monkeypatch):
    monkeypatch.setenv("DVC_STAGE", "train_vertexnet")
    monkeypatch.setenv("DVC_EXP_NAME", "tidy-exp")
    cfg = small_cfg(small_data, tmp_path, "logger.enabled=true", "trainer.max_epochs=2",
                    "trainer.limit_train_batches=2", "trainer.limit_val_batches=1",
                    "train.module.scheduler.pct_start=0.5")  # fmt: skip
    train(cfg, "vertexnet")
    client = MlflowClient(f"sqlite:///{tmp_path}/mlflow.db")
    (run,) = client.search_runs([client.get_experiment_by_name("vnrrt").experiment_id])
    tags = run.data.tags
    assert tags["dvc_stage"] == "train_vertexnet" and tags["dvc_experiment"] == "tidy-exp"
    assert tags["network"] == "vertexnet" and tags["scale"] == "smoke"
    assert tags["git_commit"] == tracking.git_commit(Path(__file__).resolve().parents[1])
    params = run.data.params
    assert params["model.net.encoder"] == "resnet18" and params["data.size"] == "64"
    assert params["networks.vertexnet.target"] == "vertex"
    assert params["net_info.encoder_frozen"] == "False" and params["net_info.weights"] == "none"
    assert len(client.get_metric_history(run.info.run_id, "val/loss")) == 2  # per epoch
    assert len(client.get_metric_history(run.info.run_id, "val/mass_near_vertex")) == 2
    assert "test/vertex_recall" in run.data.metrics and "train/loss_epoch" in run.data.metrics
    listed = {a.path for folder in ("", "figures", "checkpoints")
              for a in client.list_artifacts(run.info.run_id, folder)}  # fmt: skip
    assert {"config.yaml", "figures/val_epoch_000.png", "figures/val_epoch_001.png",
            "checkpoints/vertexnet.ckpt"} <= listed  # fmt: skip
