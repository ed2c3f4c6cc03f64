"""The MLflow runs of the trainings (stages ``train@<network>`` and
``budget_train@<network>-<steps>``): the run's Lightning ``MLFlowLogger`` with its tags and
params, and the trained network logged as an MLflow Model (pipeline trainings only: the
registry holds the networks the evaluation samples, not the budget curve's)."""

from __future__ import annotations

from pathlib import Path

from vnrrt import tracking


def make_logger(logger_cfg: tracking.LoggerConfig, scale: str, network: str, record: dict,
                settings: dict, config_text: str, budget: int | None = None):  # fmt: skip
    """The run's ``MLFlowLogger``: experiment per scale, tags, the flattened ``settings`` and
    the network's target under common keys (``network.target``, ``network.endpoints``) as
    params, the run's whole config (``config_text``) as ``config.yaml``. A training of the
    budget curve (``budget``: its optimizer steps) is named ``<network> <scale> budget
    <steps>``, tagged ``budget_steps`` and has the param ``budget.steps``, so that the
    dashboard compares the budgets."""
    from hydra.utils import instantiate

    extra = {} if budget is None else {"budget_steps": str(int(budget))}
    uri, _, tags = tracking.open_experiment(
        logger_cfg, network, scale, fingerprint=record["fingerprint"], **extra
    )
    name = f"{network} {scale}" + ("" if budget is None else f" budget {int(budget)}")
    logger = instantiate(logger_cfg.lightning, run_name=name, tracking_uri=uri, tags=tags)
    target = {k: record["target"][k] for k in ("kind", "endpoints", "radius")}
    params = {**settings, "network": target}
    if budget is not None:
        params["budget"] = {"steps": int(budget)}
    logger.log_hyperparams(tracking.flat_params(params))
    logger.log_hyperparams({f"net_info.{k}": v for k, v in record["describe"].items()})
    logger.experiment.log_text(logger.run_id, config_text, "config.yaml")
    return logger


def log_model(logger_cfg: tracking.LoggerConfig, network: str, checkpoint: Path, logger,
              datamodule, as_model: bool = True) -> None:  # fmt: skip
    """Tag the run with the checkpoint's sha256; with ``as_model`` (and ``logger.log_model``)
    log the trained network to it as an MLflow Model (pytorch flavour) with a signature and
    an input example, registered as ``<registry_prefix><network>``."""
    from vnrrt.io import sha256

    logger.experiment.set_tag(logger.run_id, "checkpoint_sha256", sha256(checkpoint))
    if not (as_model and logger_cfg.log_model):
        return
    import mlflow
    import mlflow.pytorch

    from vnrrt.model.checkpoint import load_network

    net, record = load_network(checkpoint, network)
    example = datamodule.datasets["val"][0]["image"][None].numpy()  # (1, 3, S, S) float32
    mlflow.set_tracking_uri(tracking.tracking_uri(logger_cfg.uri))
    with mlflow.start_run(run_id=logger.run_id):
        prefix = logger_cfg.registry_prefix
        registered = prefix + network if prefix else None
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
