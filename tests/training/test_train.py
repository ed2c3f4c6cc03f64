"""Training: a fast_dev_run of the real smoke config, learning on a handful of instances,
resuming from a checkpoint and clear errors for missing or mismatched checkpoints."""

import json
import shutil

import pytest
import torch
from hydra.utils import instantiate

from tests.train_helpers import QUICK, paths, small_cfg
from vnrrt.config import compose
from vnrrt.model.checkpoint import (
    CheckpointError,
    checksum_file,
    load_network,
    read_checkpoint,
    seal,
)
from vnrrt.model.metrics import VertexRecall
from vnrrt.pipeline.callbacks import LogProgress
from vnrrt.pipeline.training import run_train as train


def test_fast_dev_run_of_the_real_smoke_config(smoke_data, tmp_path):
    cfg = compose(["scale=smoke", *paths(smoke_data, tmp_path), "logger.enabled=false",
                   "+trainer.fast_dev_run=true"])  # fmt: skip
    metrics = train(cfg, "vertexnet")
    assert metrics["steps"] == 1 and 0 <= metrics["test/ap"] <= 1
    saved = json.loads((tmp_path / "metrics" / "train_vertexnet.json").read_text())
    assert saved["steps"] == 1 and "test/mass_near_vertex_uniform" in saved
    net, record = load_network(tmp_path / "models" / "vertexnet.ckpt", "vertexnet")
    assert record["target"] == {"kind": "vertex", "endpoints": "both", "radius": 0.0}
    assert record["net"]["encoder_width"] == cfg.model.net.encoder_width
    assert net(torch.rand(1, 3, 200, 200)).shape == (1, 2, 200, 200)


def recall_on(net, batch, mask: str = "interior") -> float:
    with torch.no_grad():
        probs = net.eval()(batch["image"]).softmax(1)[:, 1]
    return float(VertexRecall(radius=1.0, tau=0.5, mask=mask)(probs, **{mask: batch[mask]}))


@pytest.mark.slow
def test_overfitting_a_handful_of_instances_drives_interior_recall_up(small_data, tmp_path):
    """Four instances learnt by heart: the vertices between start and goal are found, not
    only the start and goal (whose disks are drawn in the input)."""
    cfg = small_cfg(small_data, tmp_path, "train.datamodule.train_instances=4",
                    "train.datamodule.batch_size=4", "trainer.max_epochs=80",
                    "trainer.limit_val_batches=0", "train.datamodule.target_radius=1.0",
                    "train.module.scheduler=null", "train.module.optimizer.lr=3e-3")  # fmt: skip
    dm = instantiate(cfg.train.datamodule, target="vertex", target_radius=1.0)
    dm.setup("fit")
    batch = next(iter(dm.train_dataloader()))
    assert len(batch["image"]) == 4
    torch.manual_seed(0)
    assert batch["interior"].sum() >= 4  # interior vertices to find
    before = recall_on(instantiate(cfg.model.net), batch)
    train(cfg, "vertexnet")
    net = load_network(tmp_path / "models" / "vertexnet.ckpt")[0]
    after = recall_on(net, batch)
    assert before == 0.0 and after >= 0.8, (before, after)
    assert recall_on(net, batch, "endpoints") >= 0.8


def test_a_resumed_run_ends_where_an_uninterrupted_one_does(small_data, tmp_path, monkeypatch):
    """Kill a 2-epoch run after epoch 0 and run the stage again: it resumes by itself from
    its last.ckpt (same settings), so steps, schedule, batches and the final weights equal
    those of a run never stopped; the folder of last.ckpt is gone after success."""
    two = [*QUICK, "trainer.max_epochs=2", "train.module.scheduler.pct_start=0.5"]
    full = train(small_cfg(small_data, tmp_path / "full", *two), "vertexnet")

    def crash(self, trainer, pl_module):
        if trainer.current_epoch == 1:
            raise RuntimeError("interrupted")

    cut = small_cfg(small_data, tmp_path / "cut", *two)
    with monkeypatch.context() as m:
        m.setattr(LogProgress, "on_train_epoch_start", crash)
        with pytest.raises(RuntimeError, match="interrupted"):
            train(cut, "vertexnet")
    last = tmp_path / "cut" / "models" / "checkpoints" / "vertexnet" / "last.ckpt"
    assert read_checkpoint(last)["global_step"] == 2
    resumed = train(cut, "vertexnet")  # the same stage again, nothing said about resuming
    assert resumed["steps"] == full["steps"] == 4 and resumed["epochs"] == 2
    assert (resumed["resumed_from_step"], full["resumed_from_step"]) == (2, 0)
    # the throughput counts this run's 2 steps only (batch size from the config)
    batch = cut.train.datamodule.batch_size
    assert resumed["train_images_per_s"] * resumed["fit_seconds"] == pytest.approx(2 * batch)
    want = read_checkpoint(tmp_path / "full" / "models" / "vertexnet.ckpt")["state_dict"]
    got = read_checkpoint(tmp_path / "cut" / "models" / "vertexnet.ckpt")["state_dict"]
    for key, value in want.items():
        torch.testing.assert_close(got[key], value, msg=key)
    assert not last.parent.exists()


def test_a_last_checkpoint_of_other_settings_is_not_resumed(small_data, tmp_path, caplog):
    cfg = small_cfg(small_data, tmp_path, *QUICK)
    train(cfg, "vertexnet")
    last = tmp_path / "models" / "checkpoints" / "vertexnet" / "last.ckpt"
    last.parent.mkdir(parents=True)
    shutil.copy(tmp_path / "models" / "vertexnet.ckpt", last)  # as if left by another run
    other = small_cfg(small_data, tmp_path, *QUICK, "train.module.optimizer.lr=0.5")
    with caplog.at_level("WARNING"):
        metrics = train(other, "vertexnet")
    assert "restarting vertexnet from scratch" in caplog.text and metrics["steps"] == 2


def test_stale_running_runs_of_the_stage_are_marked_killed(small_data, tmp_path, monkeypatch):
    """A SIGKILLed training cannot end its MLflow run; the next run of that stage does."""
    from mlflow import MlflowClient

    from vnrrt.tracking import experiments
    from vnrrt.tracking import store as tracking

    monkeypatch.setenv("DVC_STAGE", "train@vertexnet")
    cfg = small_cfg(small_data, tmp_path, *QUICK, "logger.enabled=true", "logger.log_model=false")
    uri = f"sqlite:///{tmp_path}/mlflow.db"
    exp = tracking.experiment_id(cfg.logger.experiment, uri)
    client = MlflowClient(uri)
    stale = client.create_run(exp, tags=experiments.run_tags("vertexnet", "smoke"))
    other = client.create_run(exp, tags=experiments.run_tags("nrrtnet", "smoke"))
    train(cfg, "vertexnet")
    assert client.get_run(stale.info.run_id).info.status == "KILLED"
    assert client.get_run(other.info.run_id).info.status == "RUNNING"  # another stage's


@pytest.mark.parametrize(
    ("override", "message"),
    [
        ("networks.vertexnet.resume={missing}", r"checkpoint .*nothing\.ckpt does not exist"),
        ("networks.vertexnet.resume={garbage}", r"checkpoint .*garbage\.ckpt is unreadable"),
        ("networks.vertexnet.resume={other}", r"record\.network: checkpoint 'nrrtnet', config "
                                              r"'vertexnet'.*record\.target\.kind"),
        ("model.net.decoder_width=0.5", r"record\.net\.decoder_width: checkpoint 0\.25, "
                                        r"config 0\.5"),
    ],
)  # fmt: skip
def test_missing_or_mismatched_checkpoints_are_named(small_data, trained, tmp_path, override,
                                                     message):  # fmt: skip
    (tmp_path / "garbage.ckpt").write_bytes(b"not a checkpoint")
    files = {"missing": tmp_path / "nothing.ckpt", "garbage": tmp_path / "garbage.ckpt",
             "other": trained / "models" / "nrrtnet.ckpt"}  # fmt: skip
    own = f"networks.vertexnet.resume={trained / 'models' / 'vertexnet.ckpt'}"
    cfg = small_cfg(small_data, tmp_path, *QUICK, own, override.format(**files))
    with pytest.raises(CheckpointError, match=message):
        train(cfg, "vertexnet")
    assert not (tmp_path / "models" / "vertexnet.ckpt").exists()


def test_loading_checks_the_network_and_the_weights(trained, tmp_path):
    with pytest.raises(CheckpointError, match="holds 'nrrtnet', not 'vertexnet'"):
        load_network(trained / "models" / "nrrtnet.ckpt", "vertexnet")
    ckpt = read_checkpoint(trained / "models" / "vertexnet.ckpt")
    del ckpt["state_dict"]["net.head.bias"]
    torch.save(seal(ckpt), tmp_path / "cut.ckpt")  # a digest that matches: only the fit fails
    with pytest.raises(CheckpointError, match=r"cut\.ckpt does not fit the network: missing: "
                                              r"head\.bias"):  # fmt: skip
        load_network(tmp_path / "cut.ckpt")
    ckpt.pop("vnrrt")
    torch.save(ckpt, tmp_path / "foreign.ckpt")
    with pytest.raises(CheckpointError, match="not written by vnrrt.train"):
        load_network(tmp_path / "foreign.ckpt")


def test_a_bit_flipped_checkpoint_is_refused(trained, tmp_path):
    """The training stage records each checkpoint's sha256 beside it; 4 KiB of flipped bytes
    inside the tensors load as garbage weights, but the prediction stage (verify=True)
    refuses them."""
    good = trained / "models" / "vertexnet.ckpt"
    assert checksum_file(good).is_file()
    load_network(good, "vertexnet", verify=True)
    bad = tmp_path / "vertexnet.ckpt"
    data = bytearray(good.read_bytes())
    middle = len(data) // 2
    data[middle : middle + 4096] = bytes(b ^ 0xFF for b in data[middle : middle + 4096])
    bad.write_bytes(bytes(data))
    shutil.copy(checksum_file(good), checksum_file(bad))
    with pytest.raises(CheckpointError, match="does not match its recorded sha256"):
        load_network(bad, "vertexnet", verify=True)
    checksum_file(bad).unlink()
    with pytest.raises(CheckpointError, match="has no recorded sha256"):
        load_network(bad, "vertexnet", verify=True)


def test_two_runs_write_identical_checkpoints_and_metrics(small_data, tmp_path):
    """The same stage twice (here in two folders, with a time cap, one thread): identical
    checkpoint bytes, hence checksums, and identical metrics but for the timings."""
    before = torch.get_num_threads()
    try:
        runs = [train(small_cfg(small_data, tmp_path / run, *QUICK, "train.threads=1",
                                "trainer.max_time={minutes: 5}"), "vertexnet")
                for run in ("a", "b")]  # fmt: skip
    finally:
        torch.set_num_threads(before)
    files = [(tmp_path / run / "models" / "vertexnet.ckpt").read_bytes() for run in ("a", "b")]
    assert files[0] == files[1]
    timing = ("fit_seconds", "train_images_per_s")
    a, b = ({k: v for k, v in r.items() if k not in timing} for r in runs)
    assert a == b and a["threads"] == 1 and a["steps"] == 2


def test_training_metrics_update_on_every_nth_batch_only():
    from torch import nn

    from vnrrt.model.loss import FocalLoss
    from vnrrt.model.module import VertexNetModule

    module = VertexNetModule(nn.Conv2d(3, 2, 1), FocalLoss(), torch.optim.SGD,
                             train_metrics_every=3)  # fmt: skip
    module.log = module.log_dict = lambda *a, **k: None  # no trainer attached
    masks = {k: torch.zeros(2, 8, 8, dtype=torch.bool) for k in
             ("vertices", "path", "interior", "endpoints")}  # fmt: skip
    batch = {"image": torch.rand(2, 3, 8, 8), "target": torch.zeros(2, 8, 8, dtype=torch.long),
             **masks}  # fmt: skip
    metric = module.train_metrics["vertex_recall"]
    for i in range(7):
        module.training_step(batch, i)
    assert metric._update_count == 3  # batches 0, 3 and 6
    module.validation_step(batch, 1)
    assert module.val_metrics["vertex_recall"]._update_count == 1  # always in val and test
    with pytest.raises(ValueError, match="train_metrics_every"):
        VertexNetModule(nn.Conv2d(3, 2, 1), FocalLoss(), torch.optim.SGD, train_metrics_every=0)


@pytest.mark.parametrize("log_model", [True, False])
def test_the_test_metrics_are_logged_once(small_data, tmp_path, monkeypatch, log_model):
    """Each test metric is one point of the training run (not Lightning's copy and then the
    model's): linked to the logged model where the run logs one."""
    from mlflow import MlflowClient

    monkeypatch.setenv("DVC_STAGE", "train@vertexnet")
    cfg = small_cfg(small_data, tmp_path, *QUICK, "logger.enabled=true",
                    f"logger.log_model={str(log_model).lower()}")  # fmt: skip
    metrics = train(cfg, "vertexnet")
    client = MlflowClient(f"sqlite:///{tmp_path}/mlflow.db")
    run = client.get_run(metrics["mlflow_run_id"])
    tested = {k for k in metrics if k.startswith("test/")}
    assert tested and tested <= set(run.data.metrics)
    for key in tested:
        history = client.get_metric_history(run.info.run_id, key)
        assert len(history) == 1, (key, history)
        assert history[0].value == pytest.approx(metrics[key])
    if log_model:  # the same single points, linked to the logged model
        model = client.get_logged_model(metrics["mlflow_model_id"])
        assert tested <= {m.key for m in model.metrics}
    assert any(k.startswith("train/") for k in run.data.metrics)  # the curves are still there
