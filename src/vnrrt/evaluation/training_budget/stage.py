"""Entry points of the budget curve's evaluation stages (:mod:`.design` says what runs).

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

from vnrrt.config import ConfigError, sections
from vnrrt.paths import Paths

log = logging.getLogger(__name__)


def _design(cfg: DictConfig) -> dict:
    """The ``eval`` keys of :class:`.design.BudgetTrials`, typed."""
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
    from vnrrt.evaluation.training_budget.design import BudgetTrials
    from vnrrt.evaluation.trials import HeatSettings, run_jobs

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
    table = run_jobs(jobs, instances, s["seed"], s["workers"], planner, heat)
    write_table(table, paths.budget_trials(steps))
    return len(table)


def report_settings(cfg: DictConfig) -> dict:
    """What stage ``budget_report@<name>`` reads, typed (keyed by config section)."""
    from vnrrt.evaluation.config import Rules, StatsConfig
    from vnrrt.training.budget import BudgetConfig

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
    from vnrrt.evaluation.training_budget.design import BudgetTrials
    from vnrrt.io import read_json

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
    from vnrrt.evaluation.training_budget.summary import analyze_budgets
    from vnrrt.io import read_json, write_json, write_text

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
    from vnrrt.evaluation.training_budget.design import BudgetTrials
    from vnrrt.io import read_yaml

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

    from vnrrt.evaluation.training_budget.report import build_budget_report

    report = Path(paths.budget_report)
    return build_budget_report(summary, [os.path.relpath(f, report.parent) for f in figures])
