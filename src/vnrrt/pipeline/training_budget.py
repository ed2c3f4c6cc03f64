"""Entry points of the budget curve's stages (:mod:`vnrrt.studies.training_budget`).

* ``budget_train@<network>-<steps>``: one network trained for one budget
  (:mod:`vnrrt.studies.training_budget.budget`) -> ``paths.budget_training(network, steps)``;
* ``budget_predict@<steps>``: the heatmaps and heatmap metrics of one budget's networks, a
  uniform map's metrics beside them -> ``paths.budget_heatmaps(steps)``,
  ``paths.budget_predict_metrics(steps)``;
* ``budget_trials@<steps>``: the trials of one training budget on its networks' heatmaps
  (``paths.budget_heatmaps(steps)``) -> ``paths.budget_trials(steps)``;
* ``budget_report@training_budget``: every budget's trials, heatmap metrics and training
  metrics (checked complete) -> the statistics (``paths.budget_summary``), the report
  (``paths.budget_report``) and its figures (``paths.budget_figures``).
"""

from __future__ import annotations

import logging
from pathlib import Path

from omegaconf import DictConfig

from vnrrt.config import ConfigError, section, sections
from vnrrt.config.paths import Paths

log = logging.getLogger(__name__)


def run_budget_train(cfg: DictConfig, network: str, steps: int) -> dict:
    """Stage ``budget_train@<network>-<steps>``: ``network`` trained for ``steps`` optimizer
    steps with a schedule of its own (:func:`vnrrt.studies.training_budget.budget.budget_config`) ->
    ``paths.budget_training(network, steps)``, resumable as the pipeline's trainings; its
    metrics add ``budget`` (:func:`~vnrrt.studies.training_budget.budget.budget_record`)."""
    from vnrrt.pipeline.training import train_network
    from vnrrt.studies.training_budget.budget import budget_config

    files = section(cfg, "paths", Paths).budget_training(network, steps)
    return train_network(budget_config(cfg, steps), network, files, budget=int(steps))


UNIFORM = 0.5  # the constant map whose metrics are "a uniform map's" (every pixel above tau 0.5)


def run_budget_predict(cfg: DictConfig, steps: int) -> dict:
    """Stage ``budget_predict@<steps>``: the heatmaps of every instance by the networks of
    ``predict.networks`` trained for ``steps`` (``paths.budget_training``) ->
    ``heatmaps/part_0.npz`` of ``paths.budget_heatmaps(steps)``, and their metrics as stage
    ``predict_metrics`` computes them, beside those of a constant (uniform) map ``uniform``,
    -> ``paths.budget_predict_metrics(steps)``; returns what it wrote."""
    import dataclasses

    import numpy as np
    import torch

    from vnrrt.data.heatmaps import part_file, write_heatmaps
    from vnrrt.data.instances import Instances
    from vnrrt.infra.io import write_json
    from vnrrt.pipeline.predict import metric_settings, network_metrics, predict_rows, split_metrics

    paths = section(cfg, "paths", Paths)
    torch.set_num_threads(int(cfg.predict.threads))
    instances = Instances(paths.instances)
    rows = np.arange(len(instances))
    nets = {n: paths.budget_training(n, steps).checkpoint for n in cfg.predict.networks}
    maps, meta, timing = predict_rows(cfg, nets, instances, rows)
    write_heatmaps(part_file(paths.budget_heatmaps(steps), 0), instances.keys, maps,
                   networks=meta, part=0, parts=1, budget_steps=int(steps))  # fmt: skip
    ms = metric_settings(cfg)
    targets = {n: m["target"]["kind"] for n, m in meta.items()}
    flat = np.full((len(instances), instances.size, instances.size), UNIFORM, np.float16)
    out = {
        "settings": dataclasses.asdict(ms),
        "networks": network_metrics(maps, instances, ms, targets, [timing]),
        "uniform": split_metrics(flat, instances, ms),
    }
    write_json(paths.budget_predict_metrics(steps), out)
    return out


def _design(cfg: DictConfig) -> dict:
    """The ``eval`` keys of :class:`~vnrrt.studies.training_budget.design.BudgetTrials`, typed."""
    ev = cfg.eval
    return {
        "planners": [str(p) for p in ev.planners],
        "sources": {str(k): str(v) for k, v in ev.sources.items()},
        "random_initial": int(ev.random_initial),
        "random_optimal": int(ev.random_optimal),
        "any_angle": bool(ev.any_angle),
        "endpoint_radius": float(ev.endpoint_radius),
        "zero_obstacles": bool(ev.zero_obstacles),
    }


def trials_settings(cfg: DictConfig) -> dict:
    """What stage ``budget_trials@<steps>`` reads, typed (keyed by config section)."""
    from vnrrt.planners.config import PlannerConfig

    return sections(cfg, paths=Paths, planner=PlannerConfig) | {
        "eval": _design(cfg),
        "oracle": {"radius": float(cfg.oracle.radius)},
        "seed": int(cfg.seed),
        "workers": int(cfg.workers),
    }


def run_budget_trials(cfg: DictConfig, steps: int) -> int:
    """Stage ``budget_trials@<steps>`` (module doc); returns the number of trials."""
    from vnrrt.data.instances import Instances, load
    from vnrrt.evaluation.table import write_table
    from vnrrt.evaluation.trials import HeatSettings, run_jobs
    from vnrrt.studies.training_budget.design import BudgetTrials

    s = trials_settings(cfg)
    paths, planner, design = s["paths"], s["planner"], BudgetTrials(**s["eval"])
    jobs = design.jobs(Instances(paths.instances).kinds, planner.tau)
    networks = sorted({j.key.source for j in jobs if j.key.source is not None})
    indices = sorted({j.instance for j in jobs})
    heatmaps = paths.budget_heatmaps(steps)
    instances, targets = load(paths.instances, indices, networks, heatmaps, [0])
    log.info("budget %d: %d trial jobs on %d instances", steps, len(jobs), len(instances))
    heat = HeatSettings(s["oracle"]["radius"], design.endpoint_radius, targets,
                        zero_obstacles=design.zero_obstacles)  # fmt: skip
    store = paths.reuse_store("budget_trials")
    table = run_jobs(jobs, instances, s["seed"], s["workers"], planner, heat, store)
    write_table(table, paths.budget_trials(steps))
    return len(table)


def report_settings(cfg: DictConfig) -> dict:
    """What stage ``budget_report@<name>`` reads, typed (keyed by config section)."""
    from vnrrt.evaluation.config import Rules, StatsConfig
    from vnrrt.studies.training_budget.budget import BudgetConfig

    typed = sections(cfg, paths=Paths, budget=BudgetConfig, planner=Rules, stats=StatsConfig)
    return typed | {
        "eval": _design(cfg),
        "scale": {"name": str(cfg.scale.name)},
        "train": {"seed": int(cfg.train.seed)},
        "seed": int(cfg.seed),
    }


def budget_inputs(s: dict) -> list[dict]:
    """Per budget (ascending): ``{"steps", "trials": table, "predict": its heatmap metrics,
    "trainings": {network: training metrics}}``; :class:`~vnrrt.evaluation.table.TableError`
    unless each trial table holds exactly its jobs' rows."""
    from vnrrt.data.instances import Instances
    from vnrrt.evaluation.invariants import design_of
    from vnrrt.evaluation.table import TableError, read_table
    from vnrrt.infra.io import read_json
    from vnrrt.studies.training_budget.design import BudgetTrials

    paths, design, rules = s["paths"], BudgetTrials(**s["eval"]), s["planner"]
    inst = Instances(paths.instances)
    rows = sum(j.count for j in design.jobs(inst.kinds, rules.tau))
    expected = design_of(inst, rules.eps, rules.max_iterations, s["seed"], design.keys(rules.tau))
    networks = sorted({k.source for k in design.keys(rules.tau) if k.source is not None})
    out = []
    for steps in s["budget"].steps:
        table = read_table(paths.budget_trials(steps))
        if len(table) != rows:
            raise TableError(f"{paths.budget_trials(steps)} holds {len(table)} trials, not the "
                             f"{rows} of this protocol (re-run `dvc repro`)")  # fmt: skip
        expected.check(table, str(paths.budget_trials(steps)))
        trainings = {n: read_json(paths.budget_training(n, steps).metrics) for n in networks}
        predict = read_json(paths.budget_predict_metrics(steps))
        out.append({"steps": steps, "trials": table, "predict": predict, "trainings": trainings})
    return out


def run_budget_report(cfg: DictConfig, name: str) -> dict:
    """Stage ``budget_report@<name>`` (module doc); returns the summary."""
    from vnrrt.infra.io import read_json, write_json, write_text
    from vnrrt.studies.training_budget.summary import analyze_budgets

    s = report_settings(cfg)
    if name not in s["budget"].report:
        raise ConfigError(f"report {name!r} is not in budget.report {s['budget'].report}")
    paths = s["paths"]
    write_json(paths.budget_summary, analyze_budgets(budget_inputs(s), summary_settings(s)))
    summary = read_json(paths.budget_summary)  # what every reader sees: the file's numbers
    figures = save_figures(paths, summary)
    write_text(paths.budget_report, report_text(paths, summary, figures))
    return summary


def summary_settings(s: dict) -> dict:
    """What the summary records of the run (its readers take every value from there)."""
    from vnrrt.infra.io import read_yaml
    from vnrrt.studies.training_budget.design import BudgetTrials

    paper = read_yaml(s["paths"].paper_settings, "the paper's settings table", ConfigError)
    design, rules, st = BudgetTrials(**s["eval"]), s["planner"], s["stats"]
    return {
        "scale": s["scale"]["name"],
        "train_seed": s["train"]["seed"],
        "eps": rules.eps,
        "tau": rules.tau,
        "level": st.level,
        "bootstrap": st.bootstrap,
        "stops": design.stops(),
        "keys": [k.text for k in design.keys(rules.tau)],
        "ratio_keys": [k.text for k in design.ratio_keys(rules.tau)],
        "sources": design.sources,
        "paper_training_images": int(paper["paper_training_images"]),
    }


def save_figures(paths: Paths, summary: dict) -> list[Path]:
    """The speed-up figures (:mod:`vnrrt.viz.budget`), one per metric; returns the files."""
    from vnrrt.viz.budget import save_budget_figure

    written = []
    for metric in summary["metrics"]:
        out = Path(paths.budget_figures) / f"speedup_{metric}.png"
        save_budget_figure(out, summary, metric)
        written.append(out)
    return written


def report_text(paths: Paths, summary: dict, figures: list[Path]) -> str:
    """``training_budget.md`` of the summary, its figures linked relative to the report."""
    import os

    from vnrrt.studies.training_budget.report import build_budget_report

    report = Path(paths.budget_report)
    return build_budget_report(summary, [os.path.relpath(f, report.parent) for f in figures])
