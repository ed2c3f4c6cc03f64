"""Entry points of the evaluation stages: parameters in, typed arguments out, one call each.

* ``instances``: the protocol's instances with their reference lengths
  (:func:`vnrrt.evaluation.instances.build_instances`);
* ``trials@<k>``: part ``k`` of the protocol's trials (:mod:`vnrrt.evaluation.trials`);
* ``evaluate``: the parts merged once into the trial table, and its statistics
  (:func:`vnrrt.evaluation.analysis.analyze`);
* ``report``: ``paper_comparison.md``, the figures, the headline metrics and the MLflow runs
  (:mod:`vnrrt.evaluation.stage_report`).

Each function receives the parameters its ``dvc.yaml`` entry declares
(:func:`vnrrt.config.restrict`); heavy imports stay inside the functions, so a stage's code
dependencies are what it runs.
"""

from __future__ import annotations

import logging
from pathlib import Path

from omegaconf import DictConfig

from vnrrt.config import section
from vnrrt.evaluation.config import EvalConfig, StatsConfig

log = logging.getLogger(__name__)


def _protocol(cfg: DictConfig):
    """``(eval config, configurations, trial counts)`` of ``cfg`` (M-VNRRT* at every
    ``planner.taus`` value and ``planner.tau``)."""
    from vnrrt.evaluation.protocol import planner_specs, trial_counts

    ev = section(cfg, "eval", EvalConfig)
    taus = [*cfg.planner.taus, cfg.planner.tau]
    return ev, planner_specs(ev, taus), trial_counts(ev)


def run_instances(cfg: DictConfig) -> dict:
    """Stage ``instances``: named maps and ``eval.random_maps`` test instances with their
    A* and exact optima -> ``paths.instances``."""
    from vnrrt.data.manifest import verified_files
    from vnrrt.evaluation.build_instances import build_instances

    shards = [int(s) for s in cfg.scale.shards]
    files = verified_files(cfg.paths.shards, cfg.paths.manifest, shards)
    return build_instances(
        cfg.paths.instances,
        cfg.paths.named_maps,
        files,
        shards,
        int(cfg.eval.random_maps),
        int(cfg.workers),
    )


def run_trials_part(cfg: DictConfig, part: int) -> int:
    """Stage ``trials@<part>``: the trials of part ``part`` of ``eval.parts`` ->
    ``<paths.trials>/part_<part>.csv``; returns the number of trials."""
    from vnrrt.config import ConfigError, check_parts
    from vnrrt.evaluation.instances import Instances, load
    from vnrrt.evaluation.protocol import part_jobs, trial_jobs
    from vnrrt.evaluation.table import part_file, write_table
    from vnrrt.evaluation.trials import HeatSettings, run_jobs
    from vnrrt.planners.config import PlannerConfig

    ev, specs, counts = _protocol(cfg)
    planner = section(cfg, "planner", PlannerConfig)
    if part not in ev.parts:
        raise ConfigError(f"part {part} is not in eval.parts {ev.parts}")
    jobs = trial_jobs(Instances(cfg.paths.instances).kinds, specs, counts)
    jobs = part_jobs(jobs, part, len(ev.parts))
    networks = sorted({s.source for s in specs if s.source is not None})
    indices = sorted({job.instance for job in jobs})
    parts = check_parts(cfg.predict.parts, "predict.parts")
    instances, targets = load(cfg.paths.instances, indices, networks, cfg.paths.heatmaps, parts)
    log.info(
        "part %d/%d: %d trial jobs on %d instances", part, len(ev.parts), len(jobs), len(instances)
    )
    heat = HeatSettings(radius=float(cfg.oracle.radius), targets=targets)
    table = run_jobs(jobs, instances, int(cfg.seed), int(cfg.workers), planner, heat)
    write_table(table, part_file(cfg.paths.trials, part))
    return len(table)


def run_evaluate(cfg: DictConfig) -> dict:
    """Stage ``evaluate``: the trial parts merged (checked complete) -> the trial table,
    its statistics (``paths.summary``) and the convergence curves."""
    from vnrrt.evaluation.analysis import analyze, convergence_curves, load_paper_tables
    from vnrrt.evaluation.instances import Instances
    from vnrrt.evaluation.protocol import trial_jobs
    from vnrrt.evaluation.table import merge_parts, write_table
    from vnrrt.io import write_json, write_text

    ev, specs, counts = _protocol(cfg)
    eps = float(cfg.planner.eps)
    expected = sum(j.count for j in trial_jobs(Instances(cfg.paths.instances).kinds, specs, counts))
    table = merge_parts(cfg.paths.trials, ev.parts, expected)
    write_table(table, cfg.paths.trials_table)
    paper = load_paper_tables(cfg.paths.paper_tables)
    st = section(cfg, "stats", StatsConfig)
    summary = analyze(table, paper, eps, st.bootstrap, st.level)
    write_json(cfg.paths.summary, summary)
    curves = convergence_curves(table, eps)
    write_text(f"{cfg.paths.plots}/convergence.csv", curves.to_csv(index=False))
    for map_set, frame in series_per_map_set(curves).items():
        write_text(f"{cfg.paths.plots}/convergence/{map_set}.csv", frame.to_csv(index=False))
    return summary


def series_per_map_set(curves) -> dict:
    """``dvc plots`` data: per map set, the stop rule ``optimal`` curves as columns planner
    (display name), median_time_ms and cost_ratio (template ``.dvc/plots/series.json``)."""
    from vnrrt.names import display_name

    opt = curves[(curves["stop"] == "optimal") & ~curves["planner"].str.endswith("+informed")]
    out = {}
    for map_set, sub in opt.groupby("map_set", sort=False):
        frame = sub.assign(
            planner=[display_name(k) for k in sub["planner"]],
            median_time_ms=1e3 * sub["median_time"],
            cost_ratio=sub["factor"],
        )
        out[map_set] = frame[["planner", "median_time_ms", "cost_ratio"]]
    return out


def run_report(cfg: DictConfig):
    """Stage ``report``: report, figures, headline metrics and MLflow runs
    (:func:`vnrrt.evaluation.stage_report.report`)."""
    from vnrrt.evaluation.stage_report import report

    return report(cfg)


def _random_instances(path, n: int) -> tuple[list[str], list[int]]:
    """The instance kinds of the instances file and its first ``n`` random instances."""
    from vnrrt.evaluation.instances import Instances

    kinds = Instances(path).kinds
    return kinds, [i for i, k in enumerate(kinds) if k == "random"][:n]


def _run_study(cfg: DictConfig, part: int, which: str) -> int:
    """A part of the oracle study (``which='oracle'``) or of the regime sweep ->
    ``<paths.<which>>/part_<part>.csv``; returns the number of trials."""
    from vnrrt.config import ConfigError, check_parts
    from vnrrt.evaluation.instances import load
    from vnrrt.evaluation.protocol import parse_key, part_jobs, trial_jobs
    from vnrrt.evaluation.study import (
        OracleConfig,
        RegimeConfig,
        oracle_counts,
        oracle_specs,
        regime_cells,
        regime_counts,
    )
    from vnrrt.evaluation.table import part_file, write_table
    from vnrrt.evaluation.trials import HeatSettings, run_jobs
    from vnrrt.planners.config import PlannerConfig

    ev = EvalConfig(planners=list(cfg.eval.planners), sources=dict(cfg.eval.sources))
    oc, planner = section(cfg, "oracle", OracleConfig), section(cfg, "planner", PlannerConfig)
    taus = [*planner.taus, planner.tau]
    if which == "oracle":
        parts, n, specs = oc.parts, oc.random_maps, oracle_specs(oc, taus, ev.sources)
        counts, configs = oracle_counts(oc), {"": planner}
    else:
        rc = section(cfg, "regime", RegimeConfig)
        parts, n, counts = rc.parts, rc.random_maps, regime_counts()
        specs = [parse_key(k, ev.sources) for k in rc.configurations]
        configs = {label: planner.replace(**over) for label, over in regime_cells(rc).items()}
    if part not in parts:
        raise ConfigError(f"part {part} is not in {which}.parts {parts}")
    kinds, chosen = _random_instances(cfg.paths.instances, n)
    jobs = trial_jobs(kinds, specs, counts, regimes=tuple(configs), instances=chosen)
    jobs = part_jobs(jobs, part, len(parts))
    networks = sorted({s.source for s in specs if s.source and not s.source.startswith("oracle")})
    indices = sorted({job.instance for job in jobs})
    predict_parts = check_parts(cfg.predict.parts, "predict.parts")
    instances, targets = load(
        cfg.paths.instances, indices, networks, cfg.paths.heatmaps, predict_parts
    )
    heat = HeatSettings(oc.sigma, oc.floor, oc.radius, targets)
    log.info(
        "%s part %d/%d: %d jobs on %d instances", which, part, len(parts), len(jobs), len(instances)
    )
    table = run_jobs(jobs, instances, int(cfg.seed), int(cfg.workers), configs, heat)
    write_table(table, part_file(cfg.paths[which], part))
    return len(table)


def run_oracle_part(cfg: DictConfig, part: int) -> int:
    """Stage ``oracle@<part>``: part of the oracle study (:mod:`vnrrt.evaluation.study`)."""
    return _run_study(cfg, part, "oracle")


def run_regime_part(cfg: DictConfig, part: int) -> int:
    """Stage ``regime@<part>``: part of the regime sweep (:mod:`vnrrt.evaluation.study`)."""
    return _run_study(cfg, part, "regime")


def run_ideas(cfg: DictConfig) -> dict:
    """Stage ``ideas``: the oracle and regime parts merged (checked complete), their
    statistics, ``sampling_ideas.md`` and its figures."""
    from vnrrt.evaluation.ideas_report import build_ideas_report
    from vnrrt.evaluation.protocol import parse_key, planner_specs, trial_jobs
    from vnrrt.evaluation.study import (
        OracleConfig,
        RegimeConfig,
        oracle_counts,
        oracle_specs,
        regime_cells,
        regime_counts,
    )
    from vnrrt.evaluation.study_analysis import analyze_study
    from vnrrt.evaluation.table import merge_parts
    from vnrrt.io import write_json, write_text
    from vnrrt.viz.ideas import save_quality, save_regime

    ev = EvalConfig(planners=list(cfg.eval.planners), sources=dict(cfg.eval.sources))
    oc, rc = section(cfg, "oracle", OracleConfig), section(cfg, "regime", RegimeConfig)
    st = section(cfg, "stats", StatsConfig)
    taus = [*cfg.planner.taus, cfg.planner.tau]
    kinds, chosen = _random_instances(cfg.paths.instances, oc.random_maps)
    jobs = trial_jobs(
        kinds, oracle_specs(oc, taus, ev.sources), oracle_counts(oc), instances=chosen
    )
    n_oracle = sum(j.count for j in jobs)
    oracle = merge_parts(cfg.paths.oracle, oc.parts, n_oracle)
    specs = [parse_key(k, ev.sources) for k in rc.configurations]
    _, chosen = _random_instances(cfg.paths.instances, rc.random_maps)
    cells = tuple(regime_cells(rc))
    jobs = trial_jobs(kinds, specs, regime_counts(), regimes=cells, instances=chosen)
    n_regime = sum(j.count for j in jobs)
    regime = merge_parts(cfg.paths.regime, rc.parts, n_regime)
    networks = [s.key for s in planner_specs(ev, taus) if s.source]
    summary = analyze_study(oracle, regime, networks, st.bootstrap, st.level)
    write_json(cfg.paths.ideas_summary, summary)
    figs = Path(cfg.paths.figures) / "ideas"
    import pandas as pd

    curves, nets = pd.DataFrame(summary["curves"]), pd.DataFrame(summary["networks"])
    written = []
    if not curves.empty:
        save_quality(figs / "quality_curve.png", curves, nets)
        written.append("figures/ideas/quality_curve.png")
    sweep = pd.DataFrame(summary["regime"])
    for stop in ("optimal", "optimal_any_angle"):
        if not sweep.empty and stop in set(sweep["stop"]):
            save_regime(figs / f"regime_{stop}.png", sweep, stop, 0.01)
            written.append(f"figures/ideas/regime_{stop}.png")
    text = build_ideas_report(summary, str(cfg.scale.name), written)
    write_text(cfg.paths.ideas_report, text)
    if cfg.logger.enabled:
        from vnrrt.evaluation.mlflow_runs import log_ideas

        reports = Path(cfg.paths.ideas_report).parent
        log_ideas(
            cfg,
            summary,
            [
                Path(cfg.paths.ideas_report),
                Path(cfg.paths.ideas_summary),
                *(reports / f for f in written),
            ],
        )
    return summary
