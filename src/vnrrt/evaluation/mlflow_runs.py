"""The MLflow runs of the evaluation (stage ``report``) and of the oracle study and regime
sweep (stage ``ideas``): a parent run per stage in the scale's experiment, with flattened
params, headline metrics and the reports, figures and tables as artifacts, and one nested run
per planner configuration. Metric names carry their unit (``median_time_ms``)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from omegaconf import DictConfig, OmegaConf

from vnrrt import tracking
from vnrrt.config import section
from vnrrt.evaluation.config import EvalConfig
from vnrrt.evaluation.protocol import PlannerSpec, parse_key
from vnrrt.io import read_json


def metric_name(*parts: str) -> str:
    """An MLflow metric name from parts (``@`` is not allowed in names: ``_tau``)."""
    return "/".join(
        p.replace("@", "_tau").replace("[", "(").replace("]", ")").replace("+", "_") for p in parts
    )


def _flat(tree: dict, prefix: tuple = ()) -> dict[str, float]:
    out = {}
    for k, v in tree.items():
        if isinstance(v, dict):
            out.update(_flat(v, (*prefix, str(k))))
        elif isinstance(v, int | float) and np.isfinite(v):
            out[metric_name(*prefix, str(k))] = float(v)
    return out


def training_runs(cfg: DictConfig, networks: set[str]) -> dict[str, str]:
    """Tags naming the training run and checkpoint hash of every network evaluated."""
    tags = {}
    for net in sorted(networks):
        path = Path(cfg.paths.metrics) / f"train_{net}.json"
        info = read_json(path) if path.is_file() else {}
        tags[f"training_run.{net}"] = str(info.get("mlflow_run_id", "none"))
        tags[f"checkpoint_sha256.{net}"] = str(info.get("checkpoint_sha256", "none"))
    return tags


def log_evaluation(
    cfg: DictConfig, summary: dict, headline_metrics: dict, artifacts: list[Path]
) -> str:
    """A parent run (headline metrics, flattened params, training run ids, the report, figures
    and trial table) with one nested run per configuration; returns the parent's id."""
    import mlflow

    uri = tracking.tracking_uri(cfg.logger.uri)
    mlflow.set_tracking_uri(uri)
    exp = tracking.experiment_id(cfg.logger.experiment, uri, cfg.logger.artifact_location)
    scale = str(cfg.scale.name)
    ev = section(cfg, "eval", EvalConfig)
    tags = tracking.run_tags("evaluation", scale, **training_runs(cfg, set(ev.sources.values())))
    with mlflow.start_run(experiment_id=exp, run_name=f"evaluation {scale}", tags=tags) as parent:
        mlflow.log_params(
            tracking.flat_params(
                {"eval": config_dict(cfg.eval), "planner": config_dict(cfg.planner)}
            )
        )
        mlflow.log_metrics(_flat(headline_metrics))
        for key in summary["keys"]:
            with mlflow.start_run(
                experiment_id=exp, run_name=key, nested=True, tags={**tags, "planner": key}
            ):
                mlflow.log_params(_config_params(parse_key(key, ev.sources)))
                mlflow.log_metrics(_config_metrics(summary, key))
        for path in artifacts:
            if Path(path).is_file():
                mlflow.log_artifact(str(path))
        return parent.info.run_id


def _config_params(spec: PlannerSpec) -> dict[str, str]:
    """The MLflow params of one configuration: planner, mask threshold, heatmap source
    (``uniform`` for RRT*) and informed sampling."""
    return {
        "planner": spec.planner,
        "tau": "none" if spec.tau is None else f"{spec.tau:g}",
        "source": spec.source or "uniform",
        "informed": str(spec.informed).lower(),
    }


def config_dict(node) -> dict:
    """A config node as plain containers."""
    return OmegaConf.to_container(node, resolve=True)


def _config_metrics(summary: dict, key: str) -> dict[str, float]:
    """Per (stop, map set) of one configuration: success rate, median and mean time (ms),
    median iterations."""
    out = {}
    for stop, per_key in summary["cells"].items():
        for map_set, m in per_key.get(key, {}).items():
            t, it = m["time_to_stop"], m["iterations"]
            vals = {
                "success_rate": t["success_rate"],
                "median_time_ms": 1e3 * t["median"],
                "mean_time_ms": 1e3 * t["mean"],
                "median_iterations": it["median"],
            }
            for name, v in vals.items():
                if v is not None and np.isfinite(v):
                    out[metric_name(stop, map_set, name)] = float(v)
    return out


def log_ideas(cfg: DictConfig, summary: dict, artifacts: list[Path]) -> str:
    """A parent run ``ideas <scale>`` (oracle and regime settings as params, the report,
    figures and summary as artifacts) with one nested run per oracle-study configuration
    (success rate, median time in ms, speed-ups over RRT*, heatmap mass near its target)."""
    import mlflow

    uri = tracking.tracking_uri(cfg.logger.uri)
    mlflow.set_tracking_uri(uri)
    exp = tracking.experiment_id(cfg.logger.experiment, uri, cfg.logger.artifact_location)
    scale = str(cfg.scale.name)
    tags = tracking.run_tags("ideas", scale)
    with mlflow.start_run(experiment_id=exp, run_name=f"ideas {scale}", tags=tags) as parent:
        params = {"oracle": config_dict(cfg.oracle), "regime": config_dict(cfg.regime)}
        mlflow.log_params(tracking.flat_params(params))
        for key in sorted({k for per in summary["oracle"].values() for k in per}):
            with mlflow.start_run(
                experiment_id=exp, run_name=key, nested=True, tags={**tags, "planner": key}
            ):
                metrics = {}
                for stop, per in summary["oracle"].items():
                    c = per.get(key, {})
                    vals = {
                        "success_rate": c.get("success_rate"),
                        "median_time_ms": c.get("median_ms"),
                        "heat_mass": c.get("heat_mass"),
                        "speedup_iterations": c.get("iterations", {}).get("speedup"),
                        "speedup_time": c.get("time_to_stop", {}).get("speedup"),
                    }
                    metrics.update(
                        {
                            metric_name(stop, n): v
                            for n, v in vals.items()
                            if v is not None and np.isfinite(v)
                        }
                    )
                mlflow.log_metrics(metrics)
        for path in artifacts:
            if Path(path).is_file():
                mlflow.log_artifact(str(path))
        return parent.info.run_id
