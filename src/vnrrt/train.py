"""Train one network (``vertexnet`` or ``nrrtnet``) from the composed config.

Everything is built from config with ``hydra.utils.instantiate``: the network and loss
(``model``), the data module and LightningModule with its optimizer / scheduler factories
(``train``), the ``lightning.Trainer`` (``trainer``); ``networks.<name>`` picks the target and
an optional checkpoint to resume from. Outputs: ``<paths.models>/<name>.ckpt`` (the final
checkpoint, with the record of :func:`make_record`), ``<paths.metrics>/train_<name>.json``
and an MLflow run (``logger``; :mod:`vnrrt.tracking`).
"""

from __future__ import annotations

import logging
import os
import time
from pathlib import Path

import lightning as L
import torch
from hydra.utils import instantiate
from lightning.pytorch.callbacks import LearningRateMonitor, ModelCheckpoint
from omegaconf import DictConfig, OmegaConf

from vnrrt import tracking
from vnrrt.callbacks import PredictionFigures, progress_callbacks
from vnrrt.config import dump
from vnrrt.data.manifest import write_json
from vnrrt.model.checkpoint import check_checkpoint
from vnrrt.model.module import VertexNetModule

log = logging.getLogger(__name__)


def network_spec(cfg: DictConfig, network: str) -> DictConfig:
    """``networks.<network>`` (target, radius, resume); ``KeyError`` lists the known ones."""
    if network not in cfg.networks:
        raise KeyError(f"unknown network {network!r}; configured: {sorted(cfg.networks)}")
    return cfg.networks[network]


def make_record(cfg: DictConfig, network: str, net: torch.nn.Module) -> dict:
    """What a checkpoint keeps to rebuild and check its network (plain JSON-able values)."""
    spec, dm = network_spec(cfg, network), cfg.train.datamodule
    return {
        "network": network,
        "net": OmegaConf.to_container(cfg.model.net, resolve=True),
        "target": {"kind": spec.target, "radius": float(spec.radius)},
        "render": {"marker_radius": float(dm.marker_radius), "normalize": dm.normalize},
        "describe": net.describe() if hasattr(net, "describe") else {},
    }


def resolve_precision(precision: str | int, accelerator: str) -> str | int:
    """``"auto"``: ``"bf16-mixed"`` when training on a CUDA GPU, else ``"32-true"``."""
    if str(precision) != "auto":
        return precision
    gpu = accelerator in ("gpu", "cuda") or (accelerator == "auto" and torch.cuda.is_available())
    return "bf16-mixed" if gpu else "32-true"


def make_logger(cfg: DictConfig, network: str, record: dict):
    """The run's ``MLFlowLogger`` with tags, the full config as params, and the config file."""
    from lightning.pytorch.loggers import MLFlowLogger

    logger = MLFlowLogger(
        experiment_name=cfg.logger.experiment,
        run_name=f"{network}-{cfg.scale.name}",
        tracking_uri=tracking.tracking_uri(cfg.logger.uri),
        tags=tracking.run_tags(network, cfg.scale.name),
        artifact_location=tracking.artifact_location(cfg.logger.artifact_location),
    )
    # On ranks > 0 the experiment is a no-op dummy and log_hyperparams does nothing.
    logger.log_hyperparams(tracking.flat_params(cfg))
    logger.log_hyperparams({f"net_info.{k}": v for k, v in record["describe"].items()})
    logger.experiment.log_text(logger.run_id, dump(cfg), "config.yaml")
    return logger


def build_trainer(cfg: DictConfig, network: str, logger) -> L.Trainer:
    """The configured ``lightning.Trainer`` with checkpointing, progress and figure callbacks."""
    callbacks, bar = progress_callbacks(int(cfg.train.log_every_n_steps))
    ckpt_dir = Path(cfg.paths.models) / "checkpoints" / network
    # <models>/checkpoints/<network>/last.ckpt, overwritten after every epoch (for resuming)
    callbacks.append(ModelCheckpoint(ckpt_dir, "last", save_top_k=1, enable_version_counter=False))
    if logger:
        callbacks += [LearningRateMonitor("step"), PredictionFigures(cfg.train.figure_instances)]
    precision = resolve_precision(cfg.trainer.precision, cfg.trainer.accelerator)
    return instantiate(cfg.trainer, callbacks=callbacks, logger=logger or False,
                       precision=precision, enable_progress_bar=bar, _convert_="all")  # fmt: skip


def save_final(trainer: L.Trainer, out: Path) -> None:
    """Write the final checkpoint to ``out`` atomically (every rank calls, rank 0 writes)."""
    tmp = out.with_name(f"{out.name}.tmp-{os.getpid()}")
    trainer.save_checkpoint(tmp)
    if trainer.is_global_zero:
        os.replace(tmp, out)


def summary(trainer: L.Trainer, tested: dict, seconds: float, batch_size: int) -> dict:
    """Metrics JSON of a run: final val metrics, test metrics, steps, time, throughput."""
    val = {k: float(v) for k, v in trainer.callback_metrics.items() if k.startswith("val/")}
    images = trainer.global_step * batch_size * trainer.world_size
    return {**val, **{k: float(v) for k, v in tested.items()}, "epochs": trainer.current_epoch,
            "steps": trainer.global_step, "train_images": images, "fit_seconds": seconds,
            "train_images_per_s": images / max(seconds, 1e-9)}  # fmt: skip


def train(cfg: DictConfig, network: str) -> dict:
    """Train ``network`` as configured; returns (and writes) its metrics (module doc)."""
    spec = network_spec(cfg, network)
    L.seed_everything(int(cfg.seed), workers=True)
    datamodule = instantiate(cfg.train.datamodule, target=spec.target, target_radius=spec.radius)
    net, loss = instantiate(cfg.model.net), instantiate(cfg.model.loss)
    record = make_record(cfg, network, net)
    # A factory, so that Hydra leaves the ready objects (and the record's _target_) alone.
    make_module = instantiate(cfg.train.module, _partial_=True)
    module: VertexNetModule = make_module(net=net, loss=loss, record=record)
    resume = spec.resume
    if resume is not None:
        check_checkpoint(resume, record, module)
    logger = make_logger(cfg, network, record) if cfg.logger.enabled else None
    trainer = build_trainer(cfg, network, logger)
    start = time.perf_counter()
    trainer.fit(module, datamodule=datamodule, ckpt_path=resume)
    seconds = time.perf_counter() - start
    out = Path(cfg.paths.models) / f"{network}.ckpt"
    out.parent.mkdir(parents=True, exist_ok=True)
    save_final(trainer, out)
    tested = trainer.test(module, datamodule=datamodule, verbose=False)[0]
    metrics = summary(trainer, tested, seconds, int(cfg.train.datamodule.batch_size))
    if trainer.is_global_zero:
        write_json(Path(cfg.paths.metrics) / f"train_{network}.json", metrics)
        if logger and cfg.logger.log_checkpoint:
            logger.experiment.log_artifact(logger.run_id, str(out), "checkpoints")
        log.info("%s: %s", network, {k: round(v, 4) for k, v in metrics.items()})
    return metrics
