"""Entry points of the ``evaluate`` and ``report`` DVC stages, and their MLflow runs.

``evaluate`` writes the per-trial table, summary metrics and convergence curves;
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
from vnrrt.config import ScaleConfig, section
from vnrrt.data.manifest import write_json
from vnrrt.evaluation.evaluate import (
    EvalConfig,
    convergence_curves,
    evaluate,
    summary_metrics,
    write_table,
)
from vnrrt.evaluation.report import build_report, check_trials, load_paper_tables
from vnrrt.evaluation.stats import improvement_ci
from vnrrt.planners import PlannerConfig

log = logging.getLogger(__name__)


def run_evaluate(cfg: DictConfig) -> dict:
    """Stage ``evaluate``: every trial of the protocol -> ``paths.eval`` files."""
    ev = section(cfg, "eval", EvalConfig)
    planner = section(cfg, "planner", PlannerConfig)
    scale = section(cfg, "scale", ScaleConfig)
    targets = {name: cfg.networks[name].target for name in cfg.networks}
    heat = {targets[n]: f"{cfg.paths.heatmaps}/{n}.npz" for n in set(ev.networks.values())}
    args = dict(named_maps=cfg.paths.named_maps, shards_dir=cfg.paths.shards,
                shard_ids=scale.shards, heatmap_files=heat, n_random=ev.random_maps)  # fmt: skip
    trials = evaluate(args, ev, planner, targets, int(cfg.seed), int(cfg.get("workers", 0)))
    write_table(trials, cfg.paths.trials)
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

    trials = pd.read_csv(cfg.paths.trials)
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
