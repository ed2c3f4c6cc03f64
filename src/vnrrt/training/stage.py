"""Entry point of the ``train@<network>`` stages: build every object from config with
``hydra.utils.instantiate`` (the network and loss from ``model``, the DataModule and the
LightningModule factories from ``train``, the callbacks from ``callbacks``, the
``lightning.Trainer`` from ``trainer``; as lightning-hydra-template does), then call
:func:`vnrrt.training.train.fit`.

Outputs: ``<paths.models>/<network>.ckpt`` (with the record of :func:`make_record`),
``<paths.metrics>/train_<network>.json`` and an MLflow run holding the network as an MLflow
Model (pytorch flavour, signature, input example), registered as ``vnrrt-<network>``.

**Resuming**: Lightning writes ``<paths.models>/checkpoints/<network>/last.ckpt`` after every
epoch. A re-run after a kill resumes from it when it was written with the same settings (its
record's ``fingerprint``), and says why it restarts otherwise; the folder is removed after a
successful run. Resuming gives the same weights as an uninterrupted run (tested).
"""

from __future__ import annotations

import hashlib
import json
import logging
import shutil
from pathlib import Path

from omegaconf import DictConfig, OmegaConf

from vnrrt import tracking

log = logging.getLogger(__name__)
LOGGER_CALLBACKS = ("learning_rate_monitor", "prediction_figures")  # need an MLflow logger


def network_spec(cfg: DictConfig, network: str) -> DictConfig:
    """``networks.<network>`` (target, endpoints, resume); ``ConfigError`` lists the known ones."""
    if network not in cfg.networks:
        from vnrrt.config import ConfigError

        raise ConfigError(f"unknown network {network!r}; configured: {sorted(cfg.networks)}")
    return cfg.networks[network]


def fingerprint(cfg: DictConfig, network: str) -> str:
    """sha256 of everything that determines the trained weights: seed, model, train,
    trainer, callbacks and the network's target (not paths, logger or workers)."""
    keys = ("seed", "model", "train", "trainer", "callbacks")
    doc = {
        k: OmegaConf.to_container(cfg[k], resolve=True)
        if isinstance(cfg[k], DictConfig)
        else cfg[k]
        for k in keys
        if k in cfg
    }
    spec = OmegaConf.to_container(network_spec(cfg, network), resolve=True)
    doc["network"] = {k: v for k, v in spec.items() if k != "resume"}
    places = {str(v): f"<paths.{k}>" for k, v in (cfg.get("paths") or {}).items()}
    return hashlib.sha256(json.dumps(_unplaced(doc, places), sort_keys=True).encode()).hexdigest()


def _unplaced(doc, places: dict[str, str]):
    """``doc`` with every string under a ``paths`` folder written relative to its key, so
    that the same run in another folder has the same fingerprint."""
    if isinstance(doc, dict):
        return {k: _unplaced(v, places) for k, v in doc.items()}
    if isinstance(doc, list):
        return [_unplaced(v, places) for v in doc]
    if isinstance(doc, str):
        for folder, key in sorted(places.items(), key=lambda kv: -len(kv[0])):
            if folder and doc.startswith(folder):
                return key + doc[len(folder) :]
    return doc


def make_record(cfg: DictConfig, network: str, net) -> dict:
    """What a checkpoint keeps to rebuild and check its network (plain JSON-able values)."""
    spec, dm = network_spec(cfg, network), cfg.train.datamodule
    return {
        "network": network,
        "net": OmegaConf.to_container(cfg.model.net, resolve=True),
        "target": {
            "kind": spec.target,
            "endpoints": spec.endpoints,
            "radius": float(dm.target_radius),
        },
        "render": {"marker_radius": float(dm.marker_radius), "normalize": dm.normalize},
        "describe": net.describe() if hasattr(net, "describe") else {},
        "fingerprint": fingerprint(cfg, network),
    }


def resume_from(cfg: DictConfig, network: str, record: dict) -> Path | None:
    """The checkpoint to resume from: ``networks.<network>.resume`` if set, else the last
    checkpoint of an interrupted run with the same settings (module doc), else None."""
    from vnrrt.model.checkpoint import CheckpointError, read_checkpoint
    from vnrrt.model.module import RECORD_KEY

    explicit = network_spec(cfg, network).resume
    if explicit is not None:
        return Path(explicit)
    last = Path(cfg.paths.models) / "checkpoints" / network / "last.ckpt"
    if not last.is_file():
        return None
    try:
        saved = read_checkpoint(last)[RECORD_KEY].get("fingerprint")
    except CheckpointError as err:
        log.warning("restarting %s from scratch: %s", network, err)
        return None
    if saved != record["fingerprint"]:
        log.warning("restarting %s from scratch: %s was written with other settings", network, last)
        return None
    log.info("resuming %s from %s (an interrupted run with the same settings)", network, last)
    return last


def build_callbacks(cfg: DictConfig, network: str, with_logger: bool) -> list:
    """The ``callbacks`` group instantiated; the checkpoint goes to
    ``<paths.models>/checkpoints/<network>``; logger-only callbacks need a logger."""
    from hydra.utils import instantiate

    out = []
    for name, node in (cfg.get("callbacks") or {}).items():
        if node is None or (name in LOGGER_CALLBACKS and not with_logger):
            continue
        extra = {}
        if name == "model_checkpoint":
            extra["dirpath"] = str(Path(cfg.paths.models) / "checkpoints" / network)
        out.append(instantiate(node, **extra))
    return out


def make_logger(cfg: DictConfig, network: str, record: dict):
    """The run's ``MLFlowLogger``: experiment per scale, tags, params, the config file."""
    from hydra.utils import instantiate

    scale = str(cfg.scale.name)
    uri, _, tags = tracking.open_experiment(
        cfg.logger, network, scale, fingerprint=record["fingerprint"]
    )
    logger = instantiate(
        cfg.logger.lightning, run_name=f"{network} {scale}", tracking_uri=uri, tags=tags
    )
    logger.log_hyperparams(tracking.flat_params(cfg))
    logger.log_hyperparams({f"net_info.{k}": v for k, v in record["describe"].items()})
    logger.experiment.log_text(logger.run_id, OmegaConf.to_yaml(cfg), "config.yaml")
    return logger


def one_handler() -> None:
    """Let Lightning's log lines reach the root handler once (Lightning installs handlers of
    its own on import, and its lines were printed twice under the stages' logging setup)."""
    for name in ("lightning", "lightning.pytorch", "lightning.fabric"):
        lg = logging.getLogger(name)
        lg.handlers.clear()
        lg.propagate = True


def fix_threads(threads: int | None) -> int:
    """Set torch's intra-op thread count (None: keep torch's default, the cores); returns
    the count in use. Float sums may differ between thread counts, so a run's metrics
    record it: equal checkpoints need equal counts."""
    import torch

    if threads is not None:
        if int(threads) < 1:
            raise ValueError(f"train.threads must be >= 1 or null, got {threads!r}")
        torch.set_num_threads(int(threads))
    return torch.get_num_threads()


def run_train(cfg: DictConfig, network: str) -> dict:
    """Stage ``train@<network>``: train ``network`` as configured (module doc); returns and
    writes its metrics."""
    uri = tracking.configure(cfg.logger.uri)  # before Lightning (and its MLflow logger) is imported
    if cfg.logger.enabled:
        tracking.check_store(uri)  # an unreachable server fails here, before any work
    import lightning as L
    from hydra.utils import instantiate

    one_handler()

    from vnrrt.model.checkpoint import check_checkpoint
    from vnrrt.training.train import fit, resolve_precision

    spec = network_spec(cfg, network)
    threads = fix_threads(cfg.train.get("threads"))
    L.seed_everything(int(cfg.train.get("seed", cfg.seed)), workers=True)
    datamodule = instantiate(
        cfg.train.datamodule, target=spec.target, target_endpoints=spec.endpoints
    )
    net, loss = instantiate(cfg.model.net), instantiate(cfg.model.loss)
    record = make_record(cfg, network, net)
    make_module = instantiate(cfg.train.module, _partial_=True)
    module = make_module(net=net, loss=loss, record=record)
    resume = resume_from(cfg, network, record)
    if resume is not None:
        check_checkpoint(resume, record, module)
    logger = make_logger(cfg, network, record) if cfg.logger.enabled else None
    callbacks = build_callbacks(cfg, network, logger is not None)
    bar = any(type(c).__name__ == "TQDMProgressBar" for c in callbacks)
    precision = resolve_precision(cfg.trainer.precision, cfg.trainer.accelerator)
    trainer = instantiate(
        cfg.trainer,
        callbacks=callbacks,
        logger=logger or False,
        precision=precision,
        enable_progress_bar=bar,
        _convert_="all",
    )
    out = Path(cfg.paths.models) / f"{network}.ckpt"
    metrics_file = Path(cfg.paths.metrics) / f"train_{network}.json"
    metrics = fit(
        module, datamodule, trainer, out, metrics_file, int(cfg.train.datamodule.batch_size), resume
    )
    if trainer.is_global_zero:
        if logger is not None:
            metrics["mlflow_run_id"] = logger.run_id
            log_model(cfg, network, out, logger, datamodule)
        from vnrrt.io import write_json
        from vnrrt.model.checkpoint import write_checksum

        metrics["checkpoint_sha256"] = write_checksum(out)
        metrics["threads"] = threads
        write_json(metrics_file, metrics)
        shutil.rmtree(Path(cfg.paths.models) / "checkpoints" / network, ignore_errors=True)
    return metrics


def log_model(cfg: DictConfig, network: str, checkpoint: Path, logger, datamodule) -> None:
    """Log the trained network to the run as an MLflow Model (pytorch flavour) with a
    signature and an input example, and register it as ``vnrrt-<network>``."""
    from vnrrt.io import sha256

    logger.experiment.set_tag(logger.run_id, "checkpoint_sha256", sha256(checkpoint))
    if not cfg.logger.log_model:
        return
    import mlflow
    import mlflow.pytorch

    from vnrrt.model.checkpoint import load_network

    net, record = load_network(checkpoint, network)
    example = datamodule.datasets["val"][0]["image"][None].numpy()  # (1, 3, S, S) float32
    mlflow.set_tracking_uri(tracking.tracking_uri(cfg.logger.uri))
    with mlflow.start_run(run_id=logger.run_id):
        registered = cfg.logger.registry_prefix + network if cfg.logger.registry_prefix else None
        # pickle: load_model returns the nn.Module itself (any batch size; needs vnrrt installed)
        mlflow.pytorch.log_model(
            net,
            name="model",
            input_example=example,
            registered_model_name=registered,
            serialization_format="pickle",
            # how to draw its input image, and what it predicts (checked by vnrrt.predict)
            metadata={"render": dict(record["render"]), "target": dict(record["target"])},
        )
