"""Training one network of a GPU run: the project's LightningModule, DataModule and
:func:`vnrrt.training.train.fit`, built from the bundle's config without Hydra, for a planned
number of steps (a whole one-cycle schedule) capped by the network's share of the budget.
"""

from __future__ import annotations

import csv
import io
import logging
import time
from datetime import timedelta
from pathlib import Path

import lightning as L
import torch
from lightning.pytorch.callbacks import Callback
from lightning.pytorch.loggers import CSVLogger

from vnrrt.data.datamodule import ShardDataModule
from vnrrt.data.splits import evenly_spaced
from vnrrt.infra.io import sha256
from vnrrt.model.module import VertexNetModule
from vnrrt.pipeline.callbacks import LogProgress
from vnrrt.pipeline.gpu.plan import build
from vnrrt.training.train import fit

log = logging.getLogger(__name__)
MODULE_TARGET = "vnrrt.model.module.VertexNetModule"
STEP_SLACK = 0.85  # planned steps fill this much of the share (worker start, validation)
TIME_CAP = 0.9  # training stops at this much of the share (the final validation, the test)
VALIDATIONS = 4  # validations per training, evenly spaced in steps
WARMUP_STEPS = 5  # left out of the steady throughput (cuDNN autotuning, compilation)


class TrainingModule(VertexNetModule):
    """:class:`VertexNetModule` whose training steps may run a compiled network
    (:meth:`compile_training`); validation, test and prediction stay eager, so eval mode
    compiles nothing, and the state dict keeps the keys of the plain network."""

    def compile_training(self) -> None:
        self.__dict__["_compiled"] = torch.compile(self.net)  # not a registered submodule

    def forward(self, image: torch.Tensor) -> torch.Tensor:
        """image ``(B, 3, H, W)`` -> logits ``(B, 2, H, W)``."""
        compiled = self.__dict__.get("_compiled")
        if compiled is None or not self.training:
            return super().forward(image)
        if self.channels_last:
            image = image.contiguous(memory_format=torch.channels_last)
        return compiled(image)


def make_record(cfg: dict, network: str, net) -> dict:
    """The checkpoint record (fields of :func:`vnrrt.pipeline.training.make_record`)."""
    spec, dm = cfg["networks"][network], cfg["datamodule"]
    return {
        "network": network,
        "net": cfg["net"],
        "target": {
            "kind": spec["target"],
            "endpoints": spec["endpoints"],
            "radius": float(dm["target_radius"]),
        },
        "render": {"marker_radius": float(dm["marker_radius"]), "normalize": dm["normalize"]},
        "describe": net.describe(),
    }


def make_module(cfg: dict, network: str) -> TrainingModule:
    """A fresh network (``net``), loss and module (``module``) of the bundle's config."""
    node = dict(cfg["module"])
    if node.pop("_target_", MODULE_TARGET) != MODULE_TARGET:
        raise ValueError(f"run_config.json module._target_ must be {MODULE_TARGET}")
    net, loss = build(cfg["net"]), build(cfg["loss"])
    kwargs = {k: build(v) for k, v in node.items()}
    return TrainingModule(net=net, loss=loss, record=make_record(cfg, network, net), **kwargs)


def make_datamodule(cfg: dict, work: Path, n_shards: int, network: str, batch: int,
                    workers: int, cuda: bool) -> ShardDataModule:  # fmt: skip
    """The data of ``network`` over shards ``0..n_shards-1`` in ``work``, set up, its
    training split cut to whole batches (every step has the same shape)."""
    spec, d = cfg["networks"][network], cfg["datamodule"]
    dm = ShardDataModule(
        str(work / "shards"), str(work / "manifest.json"), list(range(n_shards)),
        target=spec["target"], target_radius=d["target_radius"],
        target_endpoints=spec["endpoints"], marker_radius=d["marker_radius"],
        normalize=d["normalize"], val_fraction=d["val_fraction"],
        val_instances=d["val_instances"], test_instances=d["test_instances"],
        batch_size=batch, num_workers=workers, pin_memory=bool(d["pin_memory"]) and cuda,
        seed=cfg["seed"], shuffle_seed=cfg["train_seed"],
    )  # fmt: skip
    dm.setup()
    train = dm.datasets["train"]
    if len(train) < batch:
        raise ValueError(f"{len(train)} training instances in {n_shards} shards < batch {batch}")
    train.keys = evenly_spaced(train.keys, len(train) // batch * batch)
    return dm


class StepTimer(Callback):
    """Steady training throughput: images over the wall-clock time between consecutive
    training batch ends (data waits included), after :data:`WARMUP_STEPS` steps, leaving
    out the intervals that hold a validation."""

    def __init__(self) -> None:
        self.images, self.seconds, self._last, self._validated = 0, 0.0, None, False

    def on_train_batch_end(self, trainer, pl_module, outputs, batch, batch_idx) -> None:
        now = time.perf_counter()
        if self._last is not None and not self._validated and trainer.global_step > WARMUP_STEPS:
            self.images += len(batch["image"])
            self.seconds += now - self._last
        self._last, self._validated = now, False

    def on_validation_start(self, trainer, pl_module) -> None:
        self._validated = True

    def rate(self) -> float | None:
        return self.images / self.seconds if self.seconds > 0 else None


def planned_steps(rate: float, seconds: float, batch: int) -> tuple[int, int]:
    """Steps (a multiple of the validation interval) and the interval for ``seconds`` of
    training at ``rate`` images/s."""
    steps = max(1, int(STEP_SLACK * rate * seconds / batch))
    interval = max(1, steps // VALIDATIONS)
    return interval * max(1, steps // interval), interval


def make_trainer(cfg: dict, cuda: bool, steps: int, interval: int, seconds: float,
                 logs: Path, network: str, timer: StepTimer) -> L.Trainer:  # fmt: skip
    """A Lightning trainer for ``steps`` steps capped at :data:`TIME_CAP` of ``seconds``,
    validating every
    ``interval`` steps, logging curves to ``logs/<network>/metrics.csv``."""
    t = cfg["trainer"]
    return L.Trainer(
        accelerator="gpu" if cuda else "cpu", devices=1, precision=t["precision"],
        max_steps=steps, max_epochs=-1, max_time=timedelta(seconds=TIME_CAP * seconds),
        val_check_interval=interval, check_val_every_n_epoch=None, num_sanity_val_steps=0,
        deterministic=t["deterministic"], benchmark=t["benchmark"],
        gradient_clip_val=t["gradient_clip_val"],
        log_every_n_steps=max(1, min(int(t["log_every_n_steps"]), interval)),
        logger=CSVLogger(logs, name=network, version=0), enable_checkpointing=False,
        callbacks=[LogProgress(cfg["progress_every"]), timer], enable_progress_bar=False,
        default_root_dir=str(logs),
    )  # fmt: skip


def train_network(cfg: dict, work: Path, n_shards: int, network: str, batch: int,
                  rate: float, seconds: float, workers: int, cuda: bool,
                  compiled: bool) -> tuple[TrainingModule, dict]:  # fmt: skip
    """Train ``network`` (module doc) for ``seconds`` at about ``rate`` images/s; returns
    the trained module and the run's metrics (:func:`vnrrt.training.train.summary`, steady
    rate, planned steps, peak GPU memory, checkpoint sha256)."""
    L.seed_everything(cfg["train_seed"], workers=True)
    dm = make_datamodule(cfg, work, n_shards, network, batch, workers, cuda)
    module = make_module(cfg, network)
    if compiled:
        module.compile_training()
    steps, interval = planned_steps(rate, seconds, batch)
    timer = StepTimer()
    trainer = make_trainer(cfg, cuda, steps, interval, seconds, work / "logs", network, timer)
    if cuda:
        torch.cuda.reset_peak_memory_stats()
    ckpt = work / f"{network}.ckpt"
    metrics = fit(module, dm, trainer, ckpt, work / f"train_{network}.json", batch)
    metrics.update(
        planned_steps=steps, planned_images_per_s=rate, batch_size=batch,
        stopped_by_time=trainer.global_step < steps, compiled=compiled,
        train_images_per_s_steady=timer.rate(),
        train_instances=len(dm.datasets["train"]), checkpoint_sha256=sha256(ckpt),
        peak_gib=torch.cuda.max_memory_allocated() / 2**30 if cuda else None,
    )  # fmt: skip
    log.info("%s: %d steps of %d in %.0f s", network, trainer.global_step, batch,
             metrics["fit_seconds"])  # fmt: skip
    return module, metrics


def curves_csv(logs: Path, networks: dict[str, str]) -> str:
    """Every network's ``metrics.csv`` (Lightning's CSV logger) as one CSV text with a
    leading ``network`` column (``networks``: returned name -> trained name)."""
    rows, columns = [], ["network"]
    for name, trained in networks.items():
        path = logs / trained / "version_0" / "metrics.csv"
        with open(path, newline="") as f:
            for row in csv.DictReader(f):
                rows.append({"network": name, **row})
                columns += [c for c in row if c not in columns]
    buf = io.StringIO()
    writer = csv.DictWriter(buf, fieldnames=columns, lineterminator="\n")
    writer.writeheader()
    writer.writerows(rows)
    return buf.getvalue()
