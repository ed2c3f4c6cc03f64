"""Entry points of the budget curve's stages (:mod:`vnrrt.studies.training_budget`).

Each budget runs at every training seed of ``budget.seeds`` (the training variance):

* ``budget_train@<network>-<steps>-<seed>``: one network trained for one budget at one seed
  (:mod:`.budget_training`, a module of its own so that editing the others here leaves the
  trainings' code deps unchanged) -> ``paths.budget_training(network, steps, seed)``;
* ``budget_predict@<steps>-<seed>``: the heatmaps and heatmap metrics of one budget's
  networks, a uniform map's metrics beside them -> ``paths.budget_heatmaps(steps, seed)``,
  ``paths.budget_predict_metrics(steps, seed)``;
* ``budget_trials@<steps>-<seed>``: the trials of one budget on its networks' heatmaps (the
  named maps' too at the largest budget of ``budget.steps``) -> ``paths.budget_trials(steps,
  seed)`` (column ``network_seed``: ``seed``);
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


UNIFORM = 0.5  # the constant map whose metrics are "a uniform map's" (every pixel above tau 0.5)


def run_budget_predict(cfg: DictConfig, steps: int, seed: int) -> dict:
    """Stage ``budget_predict@<steps>-<seed>``: the heatmaps of every instance by the
    networks of ``predict.networks`` trained for ``steps`` at seed ``seed``
    (``paths.budget_training``) -> ``heatmaps/part_0.npz`` of ``paths.budget_heatmaps``, and
    their metrics as stage ``predict_metrics`` computes them, beside those of a constant
    (uniform) map ``uniform``, -> ``paths.budget_predict_metrics``; returns what it wrote."""
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
    nets = {n: paths.budget_training(n, steps, seed).checkpoint for n in cfg.predict.networks}
    maps, meta, timing = predict_rows(cfg, nets, instances, rows)
    write_heatmaps(part_file(paths.budget_heatmaps(steps, seed), 0), instances.keys, maps,
                   networks=meta, part=0, parts=1, budget_steps=int(steps),
                   train_seed=int(seed))  # fmt: skip
    ms = metric_settings(cfg)
    targets = {n: m["target"]["kind"] for n, m in meta.items()}
    flat = np.full((len(instances), instances.size, instances.size), UNIFORM, np.float16)
    out = {
        "settings": dataclasses.asdict(ms),
        "networks": network_metrics(maps, instances, ms, targets, [timing]),
        "uniform": split_metrics(flat, instances, ms),
    }
    write_json(paths.budget_predict_metrics(steps, seed), out)
    return out


def _design(cfg: DictConfig) -> dict:
    """The ``eval`` keys of :class:`~vnrrt.studies.training_budget.design.BudgetTrials`, typed."""
    from vnrrt.evaluation.config import check_cap_factor

    ev = cfg.eval
    return {
        "planners": [str(p) for p in ev.planners],
        "sources": {str(k): str(v) for k, v in ev.sources.items()},
        "named_initial": int(ev.named_initial),
        "named_optimal": int(ev.named_optimal),
        "random_initial": int(ev.random_initial),
        "random_optimal": int(ev.random_optimal),
        "any_angle": bool(ev.any_angle),
        "endpoint_radius": float(ev.endpoint_radius),
        "zero_obstacles": bool(ev.zero_obstacles),
        "cap_factor": check_cap_factor(ev.cap_factor),
    }


def trials_settings(cfg: DictConfig) -> dict:
    """What stage ``budget_trials@<steps>-<seed>`` reads, typed (keyed by config section)."""
    from vnrrt.planners.config import PlannerConfig

    return sections(cfg, paths=Paths, planner=PlannerConfig) | {
        "eval": _design(cfg),
        "budget": {"steps": [int(n) for n in cfg.budget.steps]},
        "oracle": {"radius": float(cfg.oracle.radius)},
        "seed": int(cfg.seed),
        "workers": int(cfg.workers),
    }


def run_budget_trials(cfg: DictConfig, steps: int, seed: int) -> int:
    """Stage ``budget_trials@<steps>-<seed>`` (module doc); returns the number of trials."""
    from vnrrt.data.instances import Instances, load
    from vnrrt.evaluation.table import with_network_seeds, write_table
    from vnrrt.evaluation.trials import TrialSettings, run_jobs
    from vnrrt.studies.training_budget.design import BudgetTrials, runs_named_maps

    s = trials_settings(cfg)
    paths, planner, design = s["paths"], s["planner"], BudgetTrials(**s["eval"])
    named = runs_named_maps(steps, s["budget"]["steps"])
    jobs = design.jobs(Instances(paths.instances).kinds, planner.tau, named=named)
    networks = sorted({j.key.source for j in jobs if j.key.source is not None})
    indices = sorted({j.instance for j in jobs})
    heatmaps = paths.budget_heatmaps(steps, seed)
    instances, targets = load(paths.instances, indices, networks, heatmaps, [0])
    log.info("budget %d, seed %d: %d trial jobs on %d instances", steps, seed, len(jobs),
             len(instances))  # fmt: skip
    heat = TrialSettings(s["oracle"]["radius"], design.endpoint_radius, targets,
                         zero_obstacles=design.zero_obstacles,
                         cap_factor=design.cap_factor)  # fmt: skip
    store = paths.reuse_store("budget_trials")
    table = run_jobs(jobs, instances, s["seed"], s["workers"], planner, heat, store)
    table = with_network_seeds(table, dict.fromkeys(networks, int(seed)))
    write_table(table, paths.budget_trials(steps, seed))
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
    """Per budget (ascending) and training seed (ascending): ``{"steps", "seed", "trials":
    table, "predict": its heatmap metrics, "trainings": {network: training metrics}}``;
    :class:`~vnrrt.evaluation.table.TableError` unless each trial table holds exactly its
    jobs' rows."""
    from vnrrt.data.instances import Instances
    from vnrrt.evaluation.invariants import design_of
    from vnrrt.evaluation.table import TableError, read_table
    from vnrrt.infra.io import read_json
    from vnrrt.studies.training_budget.design import BudgetTrials, runs_named_maps

    paths, design, rules = s["paths"], BudgetTrials(**s["eval"]), s["planner"]
    inst = Instances(paths.instances)
    expected = design_of(inst, rules.eps, rules.max_iterations, s["seed"], design.keys(rules.tau))
    networks = sorted({k.source for k in design.keys(rules.tau) if k.source is not None})
    out = []
    for steps in s["budget"].steps:
        jobs = design.jobs(inst.kinds, rules.tau, named=runs_named_maps(steps, s["budget"].steps))
        rows = sum(j.count for j in jobs)
        for seed in s["budget"].seeds:
            file = paths.budget_trials(steps, seed)
            table = read_table(file)
            if len(table) != rows:
                raise TableError(f"{file} holds {len(table)} trials, not the {rows} of this "
                                 "protocol (re-run `dvc repro`)")  # fmt: skip
            expected.check(table, str(file))
            trainings = {n: read_json(paths.budget_training(n, steps, seed).metrics)
                         for n in networks}  # fmt: skip
            predict = read_json(paths.budget_predict_metrics(steps, seed))
            out.append({"steps": steps, "seed": seed, "trials": table, "predict": predict,
                        "trainings": trainings})  # fmt: skip
    return out


def run_budget_report(cfg: DictConfig, name: str) -> dict:
    """Stage ``budget_report@<name>`` (module doc); returns the summary."""
    from vnrrt.infra.io import read_json, write_json, write_text
    from vnrrt.studies.paper_tables import load_paper_tables
    from vnrrt.studies.training_budget.claims import seed_claims
    from vnrrt.studies.training_budget.pooled import analyze_budgets
    from vnrrt.studies.training_budget.summary import clean

    s = report_settings(cfg)
    if name not in s["budget"].report:
        raise ConfigError(f"report {name!r} is not in budget.report {s['budget'].report}")
    paths, inputs, settings = s["paths"], budget_inputs(s), summary_settings(s)
    summary = analyze_budgets(inputs, settings)
    largest = [i for i in inputs if i["steps"] == inputs[-1]["steps"]]
    paper = load_paper_tables(paths.paper_tables)
    claims = seed_claims(largest, paper, s["stats"])
    summary["claims"] = clean(claims)
    write_json(paths.budget_summary, summary)
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
