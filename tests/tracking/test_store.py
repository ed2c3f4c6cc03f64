"""MLflow tracking: the default SQLite store, artifact roots that follow the repository, tags,
what a training run records (an MLflow Model that predicts what the checkpoint does), and the
services: an unreachable server refused at once, a locked SQLite store waited for, runs of a
killed stage (and only those) closed at the next start."""

import http.server
import importlib.metadata
import os
import shutil
import socket
import sqlite3
import subprocess
import sys
import threading
import time
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest
from mlflow import MlflowClient

from tests.train_helpers import small_cfg
from vnrrt.pipeline.training import run_train
from vnrrt.tracking import experiments
from vnrrt.tracking import store as tracking


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
    assert experiments.git_commit(tmp_path) == "unknown"  # no such ref yet
    (git / "packed-refs").write_text("# pack-refs\n" + "a" * 40 + " refs/heads/main\n")
    assert experiments.git_commit(tmp_path) == "a" * 40
    (git / "refs" / "heads" / "main").write_text("b" * 40 + "\n")
    assert experiments.git_commit(tmp_path) == "b" * 40
    (git / "HEAD").write_text("c" * 40 + "\n")  # detached
    assert experiments.git_commit(tmp_path) == "c" * 40
    assert experiments.git_commit(tmp_path / "nothing") == "unknown"


def test_params_are_flat_text_with_one_spelling_of_booleans_and_nulls():
    flat = experiments.flat_params({"a": {"b": [1, True], "c": None, "d": {"e": 0.5, "f": False}}})
    assert flat == {"a.b": "1,true", "a.c": "null", "a.d.e": "0.5", "a.d.f": "false"}


def test_a_training_run_is_recorded_in_mlflow(small_data, tmp_path, monkeypatch):
    import mlflow.pytorch

    from vnrrt.predict import heatmap
    from vnrrt.tracking.lineage import file_md5

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
    assert tags["git_commit"] == experiments.git_commit(Path(__file__).resolve().parents[2])
    params = run.data.params
    assert params["model.net.encoder"] == "resnet18" and params["network.target"] == "vertex"
    assert params["train.datamodule.batch_size"] == str(cfg.train.datamodule.batch_size)
    assert params["trainer.deterministic"] == "true" and params["model.net.weights"] == "null"
    assert not {v for v in params.values() if v in ("True", "False", "None", "none")}
    # what determines the weights: not infrastructure, not settings of other stages
    infrastructure = ("paths.", "logger.", "planner.", "eval.", "callbacks.", "net_info.")
    assert not [k for k in params if k.startswith(infrastructure) or k.endswith("_partial_")]
    assert "train.datamodule.shards_dir" not in params and "trainer.default_root_dir" not in params
    assert run.data.metrics["network/params_total"] == metrics["network"]["params_total"]
    assert len(client.get_metric_history(run.info.run_id, "val/loss")) == 2  # per epoch
    assert "test/vertex_recall" in run.data.metrics and "train/loss_epoch" in run.data.metrics
    assert any(k.startswith("system/cpu") for k in run.data.metrics)  # system metrics
    # the shards as one dataset per split, the manifest's DVC hash as digest
    inputs = {
        i.dataset.name: (i.dataset.digest, {t.key: t.value for t in i.tags}["mlflow.data.context"])
        for i in run.inputs.dataset_inputs
    }
    digest = file_md5(small_data / "manifest.json")
    assert inputs == {
        "shards smoke (train split)": (digest, "training"),
        "shards smoke (val split)": (digest, "validation"),
        "shards smoke (test split)": (digest, "test"),
    }
    # the validation figure as an MLflow image per epoch (the UI's step slider)
    images = {a.path for a in client.list_artifacts(run.info.run_id, "images")}
    assert len(images) == 2 * 2 and all("val_predictions" in p for p in images)  # png + json
    assert {"config.yaml"} <= {a.path for a in client.list_artifacts(run.info.run_id)}
    assert run.info.artifact_uri.startswith((tmp_path / "mlartifacts").as_uri())
    # The network as an MLflow Model named after it, with its test metrics; registered with a
    # description, tags and the scale's alias; loadable by URI, same heatmap as the checkpoint.
    model_info = client.get_logged_model(metrics["mlflow_model_id"])
    assert model_info.name == "vertexnet" and model_info.source_run_id == run.info.run_id
    logged = {m.key: m.value for m in model_info.metrics}
    assert logged["test/vertex_recall"] == pytest.approx(metrics["test/vertex_recall"])
    assert metrics["mlflow_model_version"] == "models:/vnrrt-vertexnet/1"
    version = client.get_model_version_by_alias("vnrrt-vertexnet", "smoke")
    assert str(version.version) == "1" and version.run_id == run.info.run_id
    assert "scale `smoke`" in version.description and "test/vertex_recall" in version.description
    assert version.tags["target"] == "vertex" and version.tags["training_run"] == run.info.run_id
    assert version.tags["checkpoint_sha256"] == metrics["checkpoint_sha256"]
    assert client.get_registered_model("vnrrt-vertexnet").description.startswith("vertexnet: a")
    note = tags["mlflow.note.content"]  # the run's description links its version
    assert "[vnrrt-vertexnet/1](#/models/vnrrt-vertexnet/versions/1)" in note and "@smoke" in note
    mlflow.set_tracking_uri(f"sqlite:///{tmp_path}/mlflow.db")
    # its pip requirements: what loading it needs, pinned to this environment's versions
    reqs = (
        Path(
            mlflow.artifacts.download_artifacts(
                f"runs:/{run.info.run_id}/vertexnet/requirements.txt"
            )
        )
        .read_text()
        .split()
    )
    installed = {n: importlib.metadata.version(n).split("+")[0] for n in ("torch", "mlflow")}
    assert {f"{n}=={v}" for n, v in installed.items()} <= set(reqs)
    assert {r.split("==")[0] for r in reqs} == {"mlflow", "cloudpickle", "numpy", "torch", "vnrrt"}
    model = mlflow.pytorch.load_model(f"runs:/{run.info.run_id}/vertexnet")
    from vnrrt.data.reader import Shard

    shard = Shard(small_data / "shards" / "shard_0.npz")
    inst = shard.instance(0)
    grid = shard.grid(inst["map_index"])
    from_ckpt = heatmap(tmp_path / "models" / "vertexnet.ckpt", grid, inst["start"], inst["goal"])
    from vnrrt.model.checkpoint import CheckpointError, load_network
    from vnrrt.predict.api import Model, load_model

    from_mlflow = heatmap(Model(model.eval(), {}), grid, inst["start"], inst["goal"])
    np.testing.assert_allclose(from_mlflow, from_ckpt, atol=1e-6)
    # ... and by URI through vnrrt.predict, with the rendering the network was trained with
    monkeypatch.setenv("MLFLOW_TRACKING_URI", f"sqlite:///{tmp_path}/mlflow.db")
    uris = (f"runs:/{run.info.run_id}/vertexnet", "models:/vnrrt-vertexnet/1",
            "models:/vnrrt-vertexnet@smoke")  # fmt: skip
    for uri in uris:
        loaded = load_model(uri)
        assert loaded.render == load_network(tmp_path / "models" / "vertexnet.ckpt")[1]["render"]
        assert loaded.record["target"]["kind"] == "vertex"  # logged: checked for a planner
        with pytest.raises(CheckpointError, match=f"network {uri} predicts vertex heatmaps, not "
                                                  "the path heatmaps"):  # fmt: skip
            heatmap(uri, grid, inst["start"], inst["goal"], target="path")
        np.testing.assert_allclose(
            heatmap(uri, grid, inst["start"], inst["goal"]), from_ckpt, atol=1e-6
        )
    assert not (tmp_path / "models" / "checkpoints" / "vertexnet").exists()  # cleaned up


def closed_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def test_an_unreachable_tracking_server_fails_at_once_before_any_work(small_data, tmp_path):
    """No minutes of MLflow's retries: the stage checks the server first (a refused
    connection here) and stops with one line naming it, before writing anything."""
    uri = f"http://127.0.0.1:{closed_port()}"
    cfg = small_cfg(small_data, tmp_path, "logger.enabled=true", f"logger.uri={uri}")
    with pytest.raises(ValueError, match=f"tracking server {uri} does not answer"):
        run_train(cfg, "vertexnet")
    assert not (tmp_path / "models").exists() and not (tmp_path / "metrics").exists()


class Health(http.server.BaseHTTPRequestHandler):
    status = 200

    def do_GET(self):  # /health and MLflow's REST API (an empty JSON object), else 404
        known = self.path == "/health" or self.path.startswith("/api/2.0/mlflow/")
        self.send_response(self.status if known else 404)
        self.end_headers()
        if known and self.status == 200:
            self.wfile.write(b"{}")

    def log_message(self, *args):
        pass


@pytest.mark.parametrize("status", [200, 401, 503])
def test_the_server_check_passes_an_answering_server_and_refuses_a_failing_one(status):
    handler = type("H", (Health,), {"status": status})
    server = http.server.ThreadingHTTPServer(("127.0.0.1", 0), handler)
    threading.Thread(target=server.serve_forever, daemon=True).start()
    uri = f"http://127.0.0.1:{server.server_address[1]}"
    try:
        if status < 500:  # up (401: behind authentication, still reachable)
            tracking.check_store(uri)
        else:
            with pytest.raises(tracking.TrackingError, match="answers HTTP 503"):
                tracking.check_store(uri)
    finally:
        server.shutdown()


def test_a_server_that_never_answers_is_given_up_after_the_check_timeout():
    with socket.socket() as silent:  # accepts connections (backlog), never replies
        silent.bind(("127.0.0.1", 0))
        silent.listen(1)
        uri = f"http://127.0.0.1:{silent.getsockname()[1]}"
        with pytest.raises(tracking.TrackingError, match="does not answer .*timed out"):
            tracking.check_store(uri, timeout=0.5)
    tracking.check_store("sqlite:////nowhere/mlflow.db")  # local stores: nothing to check


def test_a_stage_waits_out_seconds_of_sqlite_lock_contention(tmp_path):
    """Another process holds the store locked for 7 s when a stage opens it (SQLite's and
    MLflow's default waits are 5 s there): the stage waits and goes on. ~10 s: the lock
    must outlast that 5 s default."""
    uri = f"sqlite:///{tmp_path / 'mlflow.db'}"
    want = tracking.experiment_id("vnrrt-lock", uri)
    child = subprocess.Popen(
        [sys.executable, "-c", "import sys, mlflow; from vnrrt.tracking import store as tracking; "
         "print('ready', "
         "flush=True); sys.stdin.readline(); print(tracking.experiment_id('vnrrt-lock', "
         f"{uri!r}))"],
        stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
    )  # fmt: skip
    assert child.stdout.readline().strip() == "ready"
    lock = sqlite3.connect(tmp_path / "mlflow.db", isolation_level=None)
    lock.execute("BEGIN EXCLUSIVE")
    child.stdin.write("go\n")
    child.stdin.flush()
    time.sleep(7.0)
    lock.execute("COMMIT")
    lock.close()
    out, err = child.communicate(timeout=60)
    assert child.returncode == 0, err[-2000:]
    assert out.strip() == want


def dead_pid() -> str:
    """The id of a process that has ended."""
    return subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"],
                          capture_output=True, text=True, check=True).stdout.strip()  # fmt: skip


def test_only_runs_whose_process_is_gone_are_marked_killed(tmp_path):
    """Two experiments running the same stage at once (`dvc queue start -j 2`) must not close
    each other's runs: a run is stale only when its process, on this host, is gone."""
    uri = f"sqlite:///{tmp_path / 'mlflow.db'}"
    exp = tracking.experiment_id("vnrrt-smoke", uri)
    client = MlflowClient(uri)
    tags = experiments.run_tags("evaluation", "smoke")
    alive = subprocess.Popen([sys.executable, "-c", "import time; time.sleep(60)"])
    try:
        extras = {
            "killed": {"pid": dead_pid()},
            "live": {"pid": str(alive.pid)},
            "other_host": {"host": "elsewhere", "pid": dead_pid()},
        }
        runs = {
            n: client.create_run(exp, tags={**tags, **e}).info.run_id for n, e in extras.items()
        }
        marked = experiments.mark_stale_runs(uri, exp, tags)
    finally:
        alive.kill()
        alive.wait()
    assert marked == [runs["killed"]]
    status = {n: client.get_run(r).info.status for n, r in runs.items()}
    assert status == {"killed": "KILLED", "live": "RUNNING", "other_host": "RUNNING"}


def test_open_experiment_closes_a_killed_evaluation_and_its_nested_runs(tmp_path):
    """What the evaluation's MLflow code calls first: store checked, experiment id, tags
    with this process, and the runs of a killed run of the same stage marked KILLED."""
    uri = f"sqlite:///{tmp_path / 'mlflow.db'}"
    logger = SimpleNamespace(uri=uri, experiment="vnrrt-smoke", artifact_location=None)
    exp = tracking.experiment_id("vnrrt-smoke", uri)
    client = MlflowClient(uri)
    old = {**experiments.run_tags("evaluation", "smoke"), "pid": dead_pid()}
    parent = client.create_run(exp, tags=old).info.run_id
    nested = client.create_run(exp, tags={**old, "planner": "rrt_star",
                                          "mlflow.parentRunId": parent}).info.run_id  # fmt: skip
    ideas = client.create_run(exp, tags={**old, "kind": "ideas"}).info.run_id  # another stage
    got_uri, got_exp, tags = experiments.open_experiment(logger, "evaluation", "smoke")
    assert (got_uri, got_exp) == (uri, exp) and tags["pid"] == str(os.getpid())
    assert tags["host"] == socket.gethostname() and tags["kind"] == "evaluation"
    status = {r: client.get_run(r).info.status for r in (parent, nested, ideas)}
    assert status == {parent: "KILLED", nested: "KILLED", ideas: "RUNNING"}


def test_an_mlflow_model_that_cannot_be_loaded_is_one_line_exit_2(tmp_path, monkeypatch,
                                                                   capsys):  # fmt: skip
    from vnrrt.cli.main import main

    monkeypatch.setenv("MLFLOW_TRACKING_URI", f"sqlite:///{tmp_path / 'mlflow.db'}")
    np.save(tmp_path / "map.npy", np.zeros((32, 32), np.uint8))
    rc = main(["predict", "--checkpoint", "runs:/0123456789abcdef/model", "--map",
               str(tmp_path / "map.npy"), "--start", "2.5,2.5", "--goal", "30.5,30.5",
               "--out", str(tmp_path / "heat.npy")])  # fmt: skip
    err = capsys.readouterr().err  # MLflow logs its creation of the new store first
    assert rc == 2 and "Traceback" not in err
    assert err.splitlines()[-1].startswith("vnrrt predict: error: model runs:/0123456789abcdef/"
                                           "model cannot be loaded from sqlite:///")  # fmt: skip
