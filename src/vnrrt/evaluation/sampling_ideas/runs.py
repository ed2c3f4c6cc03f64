"""The MLflow run of the sampling-ideas study (stage ``ideas``): a parent run ``ideas
<scale>`` (the oracle and regime settings as params, the report, figures and summary as
artifacts) with one nested run per configuration of the protocol's cell (success rate, median
time in ms, speed-ups over RRT*, heatmap mass near its target, per stop rule)."""

from __future__ import annotations

from pathlib import Path

from vnrrt import tracking


def log_ideas(
    logger: tracking.LoggerConfig, scale: str, params: dict, summary: dict, artifacts: list[Path]
) -> str:
    """The parent run and its nested runs (module doc; ``params``: the settings to log,
    nested); returns the parent's id."""
    import mlflow

    uri, exp, tags = tracking.open_experiment(logger, "ideas", scale)
    mlflow.set_tracking_uri(uri)
    with mlflow.start_run(experiment_id=exp, run_name=f"ideas {scale}", tags=tags) as parent:
        mlflow.log_params(tracking.flat_params(params))
        for key in sorted({r["configuration"] for r in _protocol(summary)}):
            with mlflow.start_run(
                experiment_id=exp, run_name=key, nested=True, tags={**tags, "planner": key}
            ):
                mlflow.log_metrics(oracle_metrics(summary, key))
        for path in artifacts:
            if Path(path).is_file():
                mlflow.log_artifact(str(path))
        return parent.info.run_id


def _protocol(summary: dict) -> list[dict]:
    """The summary's cell rows of the protocol's cell (the paper's planner settings)."""
    from vnrrt.evaluation.sampling_ideas.design import PROTOCOL

    return [r for r in summary["cells"] if r["regime"] == PROTOCOL]


def oracle_metrics(summary: dict, key: str) -> dict[str, float]:
    """Per stop rule, one configuration's success rate, median time (ms), heatmap mass near
    its target and speed-ups over RRT* in the protocol's cell."""
    out = {}
    for c in _protocol(summary):
        if c["configuration"] != key:
            continue
        vals = {
            "success_rate": c.get("success_rate"),
            "median_time_ms": c.get("median_ms"),
            "heat_mass": c.get("heat_mass"),
            "speedup_iterations": c.get("iterations", {}).get("speedup"),
            "speedup_time": c.get("time_to_stop", {}).get("speedup"),
        }
        values = {k: v for k, v in vals.items() if v is not None}
        out.update(tracking.flat_metrics({c["stop"]: values}))
    return out
