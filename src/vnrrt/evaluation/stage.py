"""Entry points of the ``trials@<part>``, ``evaluate`` and ``report`` DVC stages, and their
MLflow runs.

``trials@<k>`` runs part ``k`` of the protocol's trials into ``<paths.trials>/part_<k>.csv``;
``evaluate`` merges the parts and writes the summary metrics and convergence curves;
``report`` turns the table into ``paper_comparison.md`` and the figures, and logs one
MLflow run per planner configuration nested under a parent ``evaluation`` run, with the
report and figures as the parent's artifacts.
"""

from __future__ import annotations

import json
import logging
from pathlib import Path

import pandas as pd
from omegaconf import DictConfig

from vnrrt import tracking
from vnrrt.config import ConfigError, ScaleConfig, check_parts, section
from vnrrt.data.manifest import write_json
from vnrrt.evaluation.evaluate import (
    EvalConfig,
    convergence_curves,
    evaluate_part,
    protocol_jobs,
    read_trials,
    summary_metrics,
    trials_file,
    write_table,
)
from vnrrt.evaluation.report import build_report, check_trials, load_paper_tables
from vnrrt.evaluation.stats import improvement_ci
from vnrrt.planners import PlannerConfig

log = logging.getLogger(__name__)


def _protocol(cfg: DictConfig) -> tuple[EvalConfig, PlannerConfig, dict, dict]:
    """The ``eval`` and ``planner`` sections, network -> heatmap source, and the
    :func:`~vnrrt.evaluation.instances.load_eval_instances` arguments of ``cfg``."""
    ev = section(cfg, "eval", EvalConfig)
    planner = section(cfg, "planner", PlannerConfig)
    scale = section(cfg, "scale", ScaleConfig)
    targets = {name: cfg.networks[name].target for name in cfg.networks}
    sources = {targets[n]: n for n in sorted(set(ev.networks.values()))}
    args = dict(named_maps=cfg.paths.named_maps, shards_dir=cfg.paths.shards,
                shard_ids=scale.shards, named_heatmaps=cfg.paths.named_heatmaps,
                heatmaps_dir=cfg.paths.heatmaps,
                parts=check_parts(cfg.predict.parts, "predict.parts"), sources=sources,
                n_random=ev.random_maps)  # fmt: skip
    return ev, planner, targets, args


def run_trials_part(cfg: DictConfig, part: int) -> int:
    """Stage ``trials@<part>``: the trials of part ``part`` of ``eval.parts`` ->
    ``<paths.trials>/part_<part>.csv``; returns the number of trials."""
    ev, planner, targets, args = _protocol(cfg)
    if part not in ev.parts:
        raise ConfigError(f"part {part} is not in eval.parts {ev.parts}")
    table = evaluate_part(
        args, ev, planner, targets, int(cfg.seed), int(cfg.get("workers", 0)), part
    )
    write_table(table, trials_file(cfg.paths.trials, part))
    return len(table)


def run_evaluate(cfg: DictConfig) -> dict:
    """Stage ``evaluate``: the parts' trials merged -> summary metrics (``eval.json``) and
    convergence curves; checks that the parts hold every trial of this config's protocol."""
    ev, planner, targets, args = _protocol(cfg)
    expected = sum(job.count for job in protocol_jobs(args, ev, planner, targets))
    trials = read_trials(cfg.paths.trials, ev.parts, expected)
    metrics = summary_metrics(trials)
    write_json(f"{cfg.paths.metrics}/eval.json", metrics)
    write_table(convergence_curves(trials, planner.eps), f"{cfg.paths.plots}/convergence.csv")
    return metrics


def improvements_over(trials: pd.DataFrame, baseline: str, stop: str) -> dict:
    """``{planner key: {map_set: (improvement, ci_low, ci_high)}}`` of time over ``baseline``."""
    t = check_trials(trials)
    t = t[(t["stop"] == stop) & t["success"]]
    out: dict = {}
    for (key, map_set), sub in t.groupby(["key", "map_set"]):
        base = t[(t["key"] == baseline) & (t["map_set"] == map_set)]["time_to_stop"]
        if key != baseline and len(base) and len(sub):
            out.setdefault(key, {})[map_set] = improvement_ci(base, sub["time_to_stop"])
    return out


def run_report(cfg: DictConfig) -> Path:
    """Stage ``report``: ``paper_comparison.md``, Fig. 5 and convergence figures, MLflow."""
    from vnrrt import viz

    trials = read_trials(cfg.paths.trials, section(cfg, "eval", EvalConfig).parts)
    paper = load_paper_tables(cfg.paths.paper_tables)
    out = Path(cfg.paths.report)
    text = build_report(trials, paper)
    from vnrrt.data.shards import atomic_write_bytes

    atomic_write_bytes(out, lambda f: f.write(text.encode()))
    figs = Path(cfg.paths.figures)
    titles = {"initial": "initial solutions", "optimal": "optimal solutions (1% of A*)",
              "optimal_any_angle": "optimal solutions (1% of any-angle)"}  # fmt: skip
    for stop in ("initial", "optimal", "optimal_any_angle"):
        viz.save_improvements(figs / f"improvement_{stop}.png",
                              improvements_over(trials, "rrt_star", stop),
                              f"Time improvement over RRT*, {titles[stop]}")  # fmt: skip
    curves = pd.read_csv(f"{cfg.paths.plots}/convergence.csv")
    viz.save_convergence_table(figs / "convergence.png", curves)
    if cfg.logger.enabled:
        log_evaluation(cfg, trials, [out, *sorted(figs.glob("*.png"))])
    return out


def _metric_name(*parts: str) -> str:
    return "/".join(p.replace("@", "_tau") for p in parts)


def log_evaluation(cfg: DictConfig, trials: pd.DataFrame, artifacts: list[Path]) -> str:
    """A parent MLflow run with one nested run per planner configuration; returns its id."""
    import mlflow

    mlflow.set_tracking_uri(tracking.tracking_uri(cfg.logger.uri))
    name = cfg.logger.experiment
    if mlflow.get_experiment_by_name(name) is None:
        mlflow.create_experiment(name, tracking.artifact_location(cfg.logger.artifact_location))
    mlflow.set_experiment(name)
    tags = {**tracking.run_tags("evaluation", cfg.scale.name), "kind": "evaluation"}
    metrics = summary_metrics(trials)
    with mlflow.start_run(run_name=f"evaluation-{cfg.scale.name}", tags=tags) as parent:
        mlflow.log_params(tracking.flat_params({k: cfg[k] for k in ("planner", "eval", "seed")}))
        for key, sub in check_trials(trials).groupby("key"):
            with mlflow.start_run(run_name=key, nested=True, tags={**tags, "planner": key}):
                mlflow.log_params({"planner": sub["planner"].iloc[0], "tau": sub["tau"].iloc[0],
                                   "trials": len(sub)})  # fmt: skip
                for stop, per_key in metrics.items():
                    for map_set, vals in per_key.get(key, {}).items():
                        mlflow.log_metrics({_metric_name(stop, map_set, m): v
                                            for m, v in vals.items() if pd.notna(v)})  # fmt: skip
                mlflow.log_text(sub.to_csv(index=False), "trials.csv")
        mlflow.log_text(json.dumps(metrics, indent=1), "eval_metrics.json")
        for path in artifacts:
            mlflow.log_artifact(str(path))
        return parent.info.run_id
