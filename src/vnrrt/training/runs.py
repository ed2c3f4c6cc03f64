"""The MLflow run of a training (stage ``train@<network>``), named ``<network> <scale>``; a
training of the budget curve (``budget_train@<network>-<steps>``) is named ``<network> <scale>
budget <steps>``, tagged ``budget_steps``, has the param ``budget.steps`` and logs no MLflow
Model (the registry holds the networks the evaluation samples, not the budget curve's).

* **Params**: what determines the weights, flattened (``seed``, ``model.*``, ``train.*``,
  ``trainer.*``) and the network's target under keys common to every network
  (``network.target``, ``network.endpoints``, ``network.target_radius``), so that comparing
  two trainings shows their difference; infrastructure (:data:`INFRASTRUCTURE`: file places,
  loader workers, callbacks, Hydra's ``_partial_``) is left out: the run's whole config is
  its ``config.yaml`` artifact. The network's parameter counts are metrics
  (``network/params_total``).
* **Inputs**: the shards as one dataset per split (``training``, ``validation``, ``test``),
  each with the DVC hash of the manifest that lists every shard's checksum as its digest.
* **System metrics** (``system/*``: CPU, memory, disk, network, GPU where there is one) every
  ``logger.system_metrics_seconds``, and a last sample when training ends.
* **The model**: the network as an MLflow Model named after it (``runs:/<run id>/<network>``)
  with its test metrics, registered as ``<registry_prefix><network>`` with a description,
  tags (scale, target, run, checkpoint hash, commit) and the alias ``@<scale>``
  (``models:/vnrrt-vertexnet@quick``): the version that scale trained last. Its pip
  requirements are :data:`MODEL_PACKAGES` at their installed versions (MLflow's own inference
  re-imports the model in a subprocess: 15 s a training).
"""

from __future__ import annotations

import logging
from pathlib import Path

from vnrrt.tracking import experiments
from vnrrt.tracking import store as tracking

log = logging.getLogger(__name__)
# flattened config keys (prefixes) that say where and how a run works, not what it learns
INFRASTRUCTURE = ("callbacks.", "train.datamodule.shards_dir", "train.datamodule.manifest",
                  "train.datamodule.num_workers", "train.datamodule.pin_memory",
                  "trainer.default_root_dir", "trainer.log_every_n_steps")  # fmt: skip
SPLITS = {"train": "training", "val": "validation", "test": "test"}  # split -> input context
# what loading the pickled network needs (vnrrt brings the rest of its own dependencies)
MODEL_PACKAGES = ("mlflow", "cloudpickle", "numpy", "torch", "vnrrt")


def model_requirements() -> list[str]:
    """The logged model's pip requirements: each of :data:`MODEL_PACKAGES` pinned to its
    installed version, without a local label (``torch==2.13.0`` for ``2.13.0+cpu``, as
    MLflow writes it); vnrrt run from a source tree without an install: its ``__version__``."""
    from importlib.metadata import PackageNotFoundError, version

    import vnrrt

    def pinned(name: str) -> str:
        try:
            v = version(name)
        except PackageNotFoundError:
            if name != "vnrrt":
                raise
            v = vnrrt.__version__
        return f"{name}=={v.split('+')[0]}"

    return [pinned(name) for name in MODEL_PACKAGES]


def run_params(settings: dict, record: dict, budget: int | None = None) -> dict:
    """The training's params (module doc) from its ``settings`` (seed, model, train, trainer,
    callbacks as plain containers), checkpoint ``record`` and budget-curve steps (or None)."""
    t = record["target"]
    network = {"target": t["kind"], "endpoints": t["endpoints"], "target_radius": t["radius"]}
    extra = {} if budget is None else {"budget": {"steps": int(budget)}}
    flat = experiments.flat_params({**settings, "network": network, **extra})
    return {
        k: v
        for k, v in flat.items()
        if not k.startswith(INFRASTRUCTURE) and not k.endswith("._partial_")
    }


def start_run(logger_cfg: experiments.LoggerConfig, scale: str, network: str, record: dict,
              settings: dict, config_text: str, budget: int | None = None):  # fmt: skip
    """The run's ``MLFlowLogger`` (experiment per scale, tags, :func:`run_params`, the
    parameter counts and ``config.yaml``) with the shard datasets logged as inputs;
    ``budget``: the steps of a budget-curve training (module doc), else None."""
    from hydra.utils import instantiate

    extra = {} if budget is None else {"budget_steps": str(int(budget))}
    uri, _, tags = experiments.open_experiment(
        logger_cfg, network, scale, fingerprint=record["fingerprint"], **extra
    )
    name = f"{network} {scale}" + ("" if budget is None else f" budget {int(budget)}")
    name = experiments.run_name(name)
    logger = instantiate(logger_cfg.lightning, run_name=name, tracking_uri=uri, tags=tags)
    logger.log_hyperparams(run_params(settings, record, budget))
    counts = {k: v for k, v in record["describe"].items() if k.startswith("params_")}
    logger.log_metrics({f"network/{k}": float(v) for k, v in counts.items()})
    logger.experiment.log_text(logger.run_id, config_text, "config.yaml")
    log_shards(logger.experiment, logger.run_id, scale, settings["train"]["datamodule"])
    return logger


def log_shards(client, run_id: str, scale: str, datamodule: dict) -> None:
    """The shards as one input dataset per split (module doc; ``datamodule``: the
    ``train.datamodule`` settings)."""
    from vnrrt.tracking import lineage

    manifest = Path(datamodule["manifest"])
    for split, context in SPLITS.items():
        name = f"shards {scale} ({split} split)"
        lineage.log_datasets(client, run_id, {name: manifest}, context)


class SystemMetrics:
    """MLflow's system-metrics monitor of run ``run_id`` sampling every ``seconds`` (None: no
    monitoring); :meth:`stop` logs a last sample, so that a short run has one too."""

    def __init__(self, run_id: str, uri: str, seconds: float | None) -> None:
        self.monitor = None
        if seconds is None:
            return
        from mlflow.system_metrics.system_metrics_monitor import SystemMetricsMonitor

        self.monitor = SystemMetricsMonitor(run_id, sampling_interval=float(seconds),
                                            tracking_uri=uri)  # fmt: skip
        self.monitor.start()

    def stop(self) -> None:
        if self.monitor is None:
            return
        m, self.monitor = self.monitor, None
        m.finish()
        m.collect_metrics()
        m.publish_metrics(m.aggregate_metrics())
        m.mlflow_logger.flush()


def log_model(logger_cfg: experiments.LoggerConfig, scale: str, network: str, checkpoint: Path,
              logger, example, tested: dict) -> dict:  # fmt: skip
    """Log the trained network to the run (module doc; ``example``: one input image,
    ``tested``: its test metrics) and register it; returns what the training metrics file
    records of it: ``mlflow_model_id`` and ``mlflow_model_version`` (``models:/<name>/<v>``,
    when registered)."""
    import mlflow
    import mlflow.pytorch

    from vnrrt.infra.io import sha256
    from vnrrt.model.checkpoint import load_network

    net, record = load_network(checkpoint, network)
    mlflow.set_tracking_uri(tracking.tracking_uri(logger_cfg.uri))
    prefix = logger_cfg.registry_prefix
    with mlflow.start_run(run_id=logger.run_id):
        # pickle: load_model returns the nn.Module itself (any batch size; needs vnrrt installed)
        info = mlflow.pytorch.log_model(
            net,
            name=network,
            input_example=example,
            registered_model_name=prefix + network if prefix else None,
            serialization_format="pickle",
            pip_requirements=model_requirements(),
            # how to draw its input image, and what it predicts (checked by vnrrt.predict)
            metadata={"render": dict(record["render"]), "target": dict(record["target"])},
            tags={"scale": scale, "target": record["target"]["kind"]},
        )
        mlflow.log_metrics(tested, model_id=info.model_id)
    out = {"mlflow_model_id": info.model_id}
    if info.registered_model_version is not None:
        name, version = prefix + network, str(info.registered_model_version)
        describe_version(logger.experiment, name, version, scale, record, logger.run_id, tested,
                         sha256(checkpoint))  # fmt: skip
        out["mlflow_model_version"] = f"models:/{name}/{version}"
    note = describe_run(network, scale, record, tested, out.get("mlflow_model_version"))
    logger.experiment.set_tag(logger.run_id, "mlflow.note.content", note)
    return out


def describe_run(network: str, scale: str, record: dict, tested: dict,
                 version: str | None) -> str:  # fmt: skip
    """The training run's markdown description: the network, its target, its test metrics
    and its registry version."""
    from vnrrt.tracking.lineage import model_version_link

    t = record["target"]
    lines = [
        f"**`{network}` trained at scale `{scale}`**: a {t['kind']} heatmap network (endpoints "
        f"{t['endpoints']}, target radius {t['radius']:g} px). Test metrics: "
        + ", ".join(f"`{k}` {v:.4g}" for k, v in sorted(tested.items())) + ".",
    ]  # fmt: skip
    if version:
        shown = version.removeprefix("models:/")
        lines += ["", f"Registered as [{shown}]({model_version_link(version)}), alias "
                  f"`@{scale}`: `vnrrt.predict.heatmap(\"{version.rsplit('/', 1)[0]}@{scale}\", "
                  "grid, start, goal)`."]  # fmt: skip
    return "\n".join(lines) + "\n"


def describe_version(client, name: str, version: str, scale: str, record: dict, run_id: str,
                     tested: dict, checkpoint_sha: str) -> None:  # fmt: skip
    """A registry version's description, tags and alias ``<scale>`` (module doc)."""
    target = record["target"]
    client.update_registered_model(
        name, description=f"{record['network']}: a {target['kind']} heatmap network of the "
        "vnrrt study (a (3, S, S) map image in, per-pixel probabilities out)."
    )  # fmt: skip
    shown = ", ".join(f"{k} {v:.4g}" for k, v in sorted(tested.items()))
    client.update_model_version(
        name, version, description=f"Trained at scale `{scale}` by run {run_id} "
        f"(target: {target['kind']}, endpoints {target['endpoints']}). Test: {shown}."
    )  # fmt: skip
    tags = {
        "scale": scale,
        "target": target["kind"],
        "endpoints": target["endpoints"],
        "training_run": run_id,
        "checkpoint_sha256": checkpoint_sha,
        "fingerprint": record["fingerprint"],
        "git_commit": experiments.git_commit(),
    }
    for key, value in tags.items():
        client.set_model_version_tag(name, version, key, value)
    client.set_registered_model_alias(name, scale, version)
