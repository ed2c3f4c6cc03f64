"""The MLflow runs of the paper comparison (stage ``report``): a parent run ``evaluation
<scale>`` in the scale's experiment, with the evaluation and planner settings as params, the
headline metrics, the report, figures and trial table as artifacts, tags naming the training
runs and checkpoints it used, and one nested run per configuration. Metric names carry their
unit (``median_time_ms``)."""

from __future__ import annotations

from pathlib import Path

from vnrrt import tracking
from vnrrt.evaluation.keys import ConfigKey
from vnrrt.io import read_json


def training_tags(trainings: dict[str, Path]) -> dict[str, str]:
    """Tags naming the training run and checkpoint hash of every network evaluated
    (``trainings``: network -> its training metrics file)."""
    tags = {}
    for net, path in sorted(trainings.items()):
        info = read_json(path) if Path(path).is_file() else {}
        tags[f"training_run.{net}"] = str(info.get("mlflow_run_id", "none"))
        tags[f"checkpoint_sha256.{net}"] = str(info.get("checkpoint_sha256", "none"))
    return tags


def log_evaluation(
    logger: tracking.LoggerConfig,
    scale: str,
    params: dict,
    sources: dict[str, str],
    summary: dict,
    headline_metrics: dict,
    artifacts: list[Path],
    trainings: dict[str, Path],
) -> str:
    """The parent run (module doc; ``params``: the settings to log, nested) with one nested
    run per configuration of ``summary`` (``sources``: ``eval.sources``); returns the
    parent's id."""
    import mlflow

    uri, exp, tags = tracking.open_experiment(
        logger, "evaluation", scale, **training_tags(trainings)
    )
    mlflow.set_tracking_uri(uri)
    with mlflow.start_run(experiment_id=exp, run_name=f"evaluation {scale}", tags=tags) as parent:
        mlflow.log_params(tracking.flat_params(params))
        mlflow.log_metrics(tracking.flat_metrics(headline_metrics))
        for text in summary["keys"]:
            with mlflow.start_run(
                experiment_id=exp, run_name=text, nested=True, tags={**tags, "planner": text}
            ):
                mlflow.log_params(config_params(ConfigKey.parse(text, sources)))
                mlflow.log_metrics(config_metrics(summary, text))
        for path in artifacts:
            if Path(path).is_file():
                mlflow.log_artifact(str(path))
        return parent.info.run_id


def config_params(key: ConfigKey) -> dict[str, str]:
    """The MLflow params of one configuration: planner, mask threshold, heatmap source
    (``uniform`` for RRT*) and informed sampling."""
    return {
        "planner": key.planner,
        "tau": "none" if key.tau is None else f"{key.tau:g}",
        "source": key.source or "uniform",
        "informed": str(key.informed).lower(),
    }


def config_metrics(summary: dict, text: str) -> dict[str, float]:
    """Per (stop, map set) of one configuration: success rate, median and mean time (ms),
    median iterations."""
    out = {}
    for stop, per_key in summary["cells"].items():
        for map_set, m in per_key.get(text, {}).items():
            t, it = m["time_to_stop"], m["iterations"]
            vals = {
                "success_rate": t["success_rate"],
                "median_time_ms": None if t["median"] is None else 1e3 * t["median"],
                "mean_time_ms": None if t["mean"] is None else 1e3 * t["mean"],
                "median_iterations": it["median"],
            }
            out.update(tracking.flat_metrics({stop: {map_set: vals}}))
    return out
