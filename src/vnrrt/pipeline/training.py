"""Entry points of the ``train@<network>`` stages, and the training of one network that the
budget curve's ``budget_train@<network>-<steps>`` runs too (:mod:`.training_budget`): build
every object from config with ``hydra.utils.instantiate`` (the network and loss from
``model``, the DataModule and the LightningModule factories from ``train``, the callbacks from
``callbacks``, the ``lightning.Trainer`` from ``trainer``; as lightning-hydra-template does),
then call :func:`vnrrt.training.train.fit`.

Outputs (:class:`vnrrt.config.paths.TrainFiles`: ``paths.training(network)``, or
``paths.budget_training(network, steps)``): the checkpoint (with the record of
:func:`make_record`) and its sidecar ``.sha256``, the metrics JSON and an MLflow run
(:mod:`vnrrt.training.runs`); a pipeline training's run holds the network as an MLflow Model
(pytorch flavour, signature, input example), registered as ``vnrrt-<network>`` with the alias
``@<scale>``.

**Resuming**: Lightning writes ``<run folder>/last.ckpt`` after every epoch. A re-run after a
kill resumes from it when it was written with the same settings (its record's
``fingerprint``), and says why it restarts otherwise; the folder is removed after a
successful run. Resuming gives the same weights as an uninterrupted run (tested).
"""

from __future__ import annotations

import dataclasses
import hashlib
import json
import logging
import shutil
from pathlib import Path

from omegaconf import DictConfig, OmegaConf

from vnrrt.config import ConfigError, section
from vnrrt.config.paths import Paths, TrainFiles
from vnrrt.tracking import experiments
from vnrrt.tracking import store as tracking

log = logging.getLogger(__name__)
LOGGER_CALLBACKS = ("learning_rate_monitor", "prediction_figures")  # need an MLflow logger
SETTINGS = ("seed", "model", "train", "trainer", "callbacks")  # what determines the weights


@dataclasses.dataclass
class NetworkSpec:
    """``networks.<network>``: its training target (``vertex`` or ``path``), the endpoints
    it marks, and an explicit checkpoint to resume from (None: an interrupted run's)."""

    target: str
    endpoints: str
    resume: str | None

    def validate(self) -> None:
        pass  # vnrrt.pipeline.validate checks target and endpoints against the data's known values


def _plain(node):
    """A config node as plain containers (a scalar as itself)."""
    return OmegaConf.to_container(node, resolve=True) if OmegaConf.is_config(node) else node


def network_spec(cfg: DictConfig, network: str) -> NetworkSpec:
    """``networks.<network>`` typed; ``ConfigError`` lists the known ones."""
    if network not in cfg.networks:
        raise ConfigError(f"unknown network {network!r}; configured: {sorted(cfg.networks)}")
    return section(cfg.networks, network, NetworkSpec)


def fingerprint(settings: dict, spec: NetworkSpec, paths: Paths) -> str:
    """sha256 of everything that determines the trained weights: ``settings`` (seed, model,
    train, trainer and callbacks as plain containers) and the network's target (not paths,
    logger or workers)."""
    doc = dict(settings)
    doc["network"] = {"target": spec.target, "endpoints": spec.endpoints}
    places = {str(v): f"<paths.{k}>" for k, v in dataclasses.asdict(paths).items()}
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


def make_record(network: str, net_config: dict, spec: NetworkSpec, dm: dict, net,
                fingerprint: str) -> dict:  # fmt: skip
    """What a checkpoint keeps to rebuild and check its network (plain JSON-able values):
    ``net_config`` (``model.net``), the target, and the input rendering of the datamodule
    settings ``dm`` (``train.datamodule``)."""
    return {
        "network": network,
        "net": net_config,
        "target": {
            "kind": spec.target,
            "endpoints": spec.endpoints,
            "radius": float(dm["target_radius"]),
        },
        "render": {"marker_radius": float(dm["marker_radius"]), "normalize": dm["normalize"]},
        "describe": net.describe() if hasattr(net, "describe") else {},
        "fingerprint": fingerprint,
    }


def resume_from(spec: NetworkSpec, last: Path, network: str, record: dict) -> Path | None:
    """The checkpoint to resume from: ``spec.resume`` if set, else ``last`` (the last
    checkpoint of an interrupted run) when it has the same settings (module doc), else None."""
    from vnrrt.model.checkpoint import CheckpointError, read_checkpoint
    from vnrrt.model.record import RECORD_KEY

    if spec.resume is not None:
        return Path(spec.resume)
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


def build_callbacks(callbacks: DictConfig | None, folder: Path, with_logger: bool) -> list:
    """The ``callbacks`` group instantiated; the checkpoint goes to ``folder``; logger-only
    callbacks need a logger."""
    from hydra.utils import instantiate

    out = []
    for name, node in (callbacks or {}).items():
        if node is None or (name in LOGGER_CALLBACKS and not with_logger):
            continue
        extra = {"dirpath": str(folder)} if name == "model_checkpoint" else {}
        out.append(instantiate(node, **extra))
    return out


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


def monitored_fit(logger_cfg: experiments.LoggerConfig, logger, fit_run):
    """``fit_run()`` with the system metrics of ``logger``'s run monitored (None: not)."""
    if logger is None:
        return fit_run()
    from vnrrt.training.runs import SystemMetrics

    monitor = SystemMetrics(
        logger.run_id, tracking.tracking_uri(logger_cfg.uri), logger_cfg.system_metrics_seconds
    )
    try:
        return fit_run()
    finally:
        monitor.stop()


def run_train(cfg: DictConfig, network: str) -> dict:
    """Stage ``train@<network>``: train ``network`` as configured (module doc); returns and
    writes its metrics."""
    return train_network(cfg, network, section(cfg, "paths", Paths).training(network))


def train_network(cfg: DictConfig, network: str, files: TrainFiles,
                  budget: int | None = None) -> dict:  # fmt: skip
    """Train ``network`` as ``cfg`` says into ``files`` (module doc); ``budget``: the steps
    of a budget-curve training (its MLflow run, no MLflow Model). The stage's parameters are
    read here; below, typed pieces."""
    logger_cfg = section(cfg, "logger", experiments.LoggerConfig)
    uri = tracking.configure(logger_cfg.uri)  # before Lightning (and its MLflow logger) imports
    if logger_cfg.enabled:
        tracking.check_store(uri)  # an unreachable server fails here, before any work
    import lightning as L
    from hydra.utils import instantiate

    one_handler()

    from vnrrt.model.checkpoint import check_checkpoint
    from vnrrt.training.train import fit, resolve_precision

    paths, spec = section(cfg, "paths", Paths), network_spec(cfg, network)
    settings = {k: _plain(cfg[k]) for k in SETTINGS if k in cfg}
    threads = fix_threads(cfg.train.get("threads"))
    L.seed_everything(int(cfg.train.get("seed", cfg.seed)), workers=True)
    datamodule = instantiate(
        cfg.train.datamodule, target=spec.target, target_endpoints=spec.endpoints
    )
    net, loss = instantiate(cfg.model.net), instantiate(cfg.model.loss)
    record = make_record(network, settings["model"]["net"], spec, settings["train"]["datamodule"],
                         net, fingerprint(settings, spec, paths))  # fmt: skip
    module = instantiate(cfg.train.module, _partial_=True)(net=net, loss=loss, record=record)
    resume = resume_from(spec, files.run_folder / "last.ckpt", network, record)
    if resume is not None:
        check_checkpoint(resume, record, module)
    logger, scale = None, str(cfg.scale.name)
    if logger_cfg.enabled:
        from vnrrt.training.runs import start_run

        text = OmegaConf.to_yaml(cfg)
        logger = start_run(logger_cfg, scale, network, record, settings, text, budget)
    callbacks = build_callbacks(cfg.get("callbacks"), files.run_folder, logger is not None)
    bar = any(type(c).__name__ == "TQDMProgressBar" for c in callbacks)
    precision = resolve_precision(cfg.trainer.precision, cfg.trainer.accelerator)
    trainer = instantiate(cfg.trainer, callbacks=callbacks, logger=logger or False,
                          precision=precision, enable_progress_bar=bar,
                          _convert_="all")  # fmt: skip
    batch = int(cfg.train.datamodule.batch_size)
    metrics = monitored_fit(logger_cfg, logger if trainer.is_global_zero else None,
                            lambda: fit(module, datamodule, trainer, files.checkpoint,
                                        files.metrics, batch, resume,
                                        with_val=budget is not None))  # fmt: skip
    if budget is not None:
        from vnrrt.studies.training_budget.budget import budget_record

        metrics["budget"] = budget_record(trainer, budget)
    if trainer.is_global_zero:
        if logger is not None:
            metrics |= finish_run(logger_cfg, scale, network, files.checkpoint, logger,
                                  datamodule, metrics, as_model=budget is None)  # fmt: skip
        from vnrrt.infra.io import write_json
        from vnrrt.model.checkpoint import write_checksum

        metrics["checkpoint_sha256"] = write_checksum(files.checkpoint)
        metrics["threads"] = threads
        metrics["batch_size"] = batch
        metrics["network"] = record["describe"]  # architecture, initialisation, parameters
        metrics["target"] = record["target"]
        write_json(files.metrics, metrics)
        shutil.rmtree(files.run_folder, ignore_errors=True)
    return metrics


def finish_run(logger_cfg: experiments.LoggerConfig, scale: str, network: str, checkpoint: Path,
               logger, datamodule, metrics: dict, as_model: bool = True) -> dict:  # fmt: skip
    """Tag the run with the checkpoint's hash and log the test metrics once: with ``as_model``
    and ``logger.log_model`` linked to the network, logged and registered
    (:func:`vnrrt.training.runs.log_model`), else to the run alone; returns what the
    training metrics file records of the run."""
    from vnrrt.infra.io import sha256
    from vnrrt.training.runs import log_model

    logger.experiment.set_tag(logger.run_id, "checkpoint_sha256", sha256(checkpoint))
    out = {"mlflow_run_id": logger.run_id}
    tested = {k: v for k, v in metrics.items() if k.startswith("test/")}
    if as_model and logger_cfg.log_model:
        example = datamodule.datasets["val"][0]["image"][None].numpy()  # (1, 3, S, S) float32
        out |= log_model(logger_cfg, scale, network, checkpoint, logger, example, tested)
    else:
        logger.log_metrics(tested, step=metrics.get("steps"))
    return out
