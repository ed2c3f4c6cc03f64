"""Entry points of the paper comparison's stages.

* ``evaluate``: the trial parts merged once (checked complete) into ``paths.trials_table``,
  every statistic of the report (``paths.summary``,
  :func:`~vnrrt.studies.paper_comparison.summary.analyze`) and the convergence curves
  (``paths.convergence``, ``paths.convergence_plots``);
* ``report``: ``paths.report`` (:func:`~vnrrt.studies.paper_comparison.report.build_report`),
  Fig. 5 and the convergence figure (``paths.evaluation_figures``), the headline metrics
  (``paths.headline``) and the
  MLflow evaluation runs (:mod:`vnrrt.studies.paper_comparison.runs`; they link the ideas run
  of ``paths.ideas_summary`` and log the heatmap parts of ``paths.heatmaps`` as datasets).
"""

from __future__ import annotations

import dataclasses
import logging
from pathlib import Path

from omegaconf import DictConfig, OmegaConf

from vnrrt.config import ConfigError, sections
from vnrrt.config.paths import Paths

log = logging.getLogger(__name__)


def evaluate_settings(cfg: DictConfig) -> dict:
    """What stage ``evaluate`` reads, typed (keyed by config section)."""
    from vnrrt.evaluation.config import EvalConfig, Rules, StatsConfig

    typed = sections(cfg, paths=Paths, eval=EvalConfig, stats=StatsConfig, planner=Rules)
    return typed | {"seed": int(cfg.seed)}


def run_evaluate(cfg: DictConfig) -> dict:
    """Stage ``evaluate`` (module doc); returns the summary."""
    from vnrrt.data.instances import Instances
    from vnrrt.evaluation.invariants import design_of
    from vnrrt.evaluation.protocol import configurations, trial_counts, trial_jobs
    from vnrrt.evaluation.table import merge_parts, write_table
    from vnrrt.infra.io import read_json, write_json, write_text
    from vnrrt.studies.paper_comparison.summary import convergence_curves

    s = evaluate_settings(cfg)
    paths, ev, rules = s["paths"], s["eval"], s["planner"]
    keys = configurations(ev, rules.mask_taus, rules.tau)
    inst = Instances(paths.instances)
    jobs = trial_jobs(inst.kinds, keys, trial_counts(ev))
    design = design_of(inst, rules.eps, rules.max_iterations, s["seed"], keys)
    table = merge_parts(paths.trials, ev.parts, sum(j.count for j in jobs), design)
    write_table(table, paths.trials_table)
    summary = evaluate_summary(table, s, read_json(paths.predict_metrics), inst.turns())
    write_json(paths.summary, summary)
    curves = convergence_curves(table, rules.eps)
    write_text(paths.convergence, curves.to_csv(index=False))
    for map_set, frame in series_per_map_set(curves).items():
        write_text(Path(paths.convergence_plots) / f"{map_set}.csv", frame.to_csv(index=False))
    return summary


def evaluate_summary(table, s: dict, predict: dict, turns: dict[int, int] | None) -> dict:
    """The summary of the merged trial ``table``
    (:func:`~vnrrt.studies.paper_comparison.summary.analyze`) with stage
    ``evaluate``'s settings ``s``, the networks' inference times of ``predict``
    (``predict.json``) and each instance's turning points ``turns`` (None: no strata)."""
    from vnrrt.studies.paper_comparison.summary import analyze
    from vnrrt.studies.paper_tables import load_paper_tables

    paper = load_paper_tables(s["paths"].paper_tables)
    inference = {n: float(m["ms_per_map"]) for n, m in predict["networks"].items()}
    return analyze(table, paper, s["planner"].eps, s["stats"], inference, turns)


def series_per_map_set(curves) -> dict:
    """``dvc plots`` data: per map set, the stop rule ``optimal`` curves as columns planner
    (display name), median_time_ms and cost_ratio (template ``.dvc/plots/series.json``)."""
    from vnrrt.evaluation.keys import is_informed, label

    opt = curves[(curves["stop"] == "optimal") & ~curves["planner"].map(is_informed)]
    out = {}
    for map_set, sub in opt.groupby("map_set", sort=False):
        frame = sub.assign(
            planner=[label(k) for k in sub["planner"]],
            median_time_ms=1e3 * sub["median_time"],
            cost_ratio=sub["factor"],
        )
        out[map_set] = frame[["planner", "median_time_ms", "cost_ratio"]]
    return out


def report_settings(cfg: DictConfig) -> dict:
    """What stage ``report`` reads, typed (keyed by config section); ``values``: the run's
    value of every setting the settings table names (``paths.paper_settings``)."""
    from vnrrt.evaluation.config import EvalConfig
    from vnrrt.planners.config import PlannerConfig
    from vnrrt.tracking.experiments import LoggerConfig

    typed = sections(cfg, paths=Paths, eval=EvalConfig, planner=PlannerConfig)
    typed |= sections(cfg, logger=LoggerConfig) | {"scale": {"name": str(cfg.scale.name)}}
    from vnrrt.infra.io import read_yaml

    settings = read_yaml(typed["paths"].paper_settings, "the paper's settings table", ConfigError)
    keys = [e["key"] for e in settings["settings"] if e.get("key")]
    values = {k: OmegaConf.to_container(v) if OmegaConf.is_config(v := OmegaConf.select(cfg, k))
              else v for k in keys}  # fmt: skip
    values["scale.maps"] = int(cfg.scale.maps_per_shard) * len(cfg.scale.shards)
    return typed | {"paper_settings": settings, "values": values}


def report_text(s: dict, summary: dict, predict: dict, trainings: dict, optima: dict,
                against: tuple[list[dict] | None, str] = (None, "")) -> str:  # fmt: skip
    """``paper_comparison.md`` from stage ``report``'s settings ``s``, the ``summary``, the
    networks' ``predict.json`` and training metrics (``trainings``: network -> metrics), the
    instances' optimal lengths (``optima``) and an ablation's claims against the default
    run (``against``: :func:`against_default`)."""
    from vnrrt.evaluation.config import mask_taus
    from vnrrt.evaluation.protocol import configurations
    from vnrrt.studies.paper_comparison.networks_report import metric_settings
    from vnrrt.studies.paper_comparison.report import ReportInputs, build_report
    from vnrrt.studies.paper_tables import load_paper_tables

    ev, planner = s["eval"], s["planner"]
    keys = configurations(ev, mask_taus(planner.taus, planner.tau), planner.tau)
    inputs = ReportInputs(
        summary,
        load_paper_tables(s["paths"].paper_tables),
        optima,
        {k.text: k.source for k in keys if k.source},
        s["scale"]["name"],
        predict["networks"],
        metric_settings(predict["settings"]),
        s["paper_settings"],
        s["values"],
        trainings,
        *against,
    )
    return build_report(inputs)


def against_default(paths: Paths, summary: dict, params: str = "params.yaml"):
    """``(changes, overrides text)`` of this run's claims against this scale's default run
    (:func:`vnrrt.evaluation.noise.changes`). The default run (no setting changed from
    ``conf/``'s composition) keeps its claims at ``paths.baseline`` and compares with
    nothing: ``(None, "")``; so does an ablation run before any default run."""
    from vnrrt.evaluation.noise import baseline_record, changes
    from vnrrt.infra.io import read_json, write_json
    from vnrrt.tracking.experiments import override_text, overrides

    changed, rows = overrides(params), summary["claims"]["rows"]
    if not changed:
        write_json(paths.baseline, baseline_record(rows))
        return None, ""
    if not Path(paths.baseline).is_file():
        return None, ""
    noise = summary.get("timing_noise", {})
    return changes(rows, read_json(paths.baseline), noise), override_text(changed)


def gpu_trainings(paths: Paths) -> dict[str, dict]:
    """The GPU-trained paper networks' training records (``paths.gpu_returned``'s
    ``metrics.json``, checked by :func:`vnrrt.data.returned.read_returned`) in the layout of
    a training metrics file, ``where`` naming the machine and the budget."""
    from vnrrt.data.returned import read_returned

    run = read_returned(paths.gpu_returned, paths.instances)["metrics"]
    where = f"{run['machine']}, a {run['budget_s'] / 60:.0f}-minute run"
    out = {}
    for name, n in run["networks"].items():
        record = {"network": n.get("params", {}), "target": n.get("target", {})}
        out[name] = {**record, **n.get("train", {}), "where": where}
    return out


def run_report(cfg: DictConfig) -> Path:
    """Stage ``report`` (module doc); returns the report's path."""
    from vnrrt.data.instances import Instances
    from vnrrt.infra.io import read_json, write_json, write_text
    from vnrrt.infra.machine import describe
    from vnrrt.studies.paper_comparison.headline import headline
    from vnrrt.tracking import store as tracking

    s = report_settings(cfg)
    paths, ev, planner, logger, scale = s["paths"], s["eval"], s["planner"], s["logger"], s["scale"]
    if logger.enabled:  # an unreachable store fails here, before any work
        tracking.check_store(tracking.tracking_uri(logger.uri))
    summary, predict = read_json(paths.summary), read_json(paths.predict_metrics)
    trainings = {n: read_json(paths.train_metrics(n)) for n in predict["networks"]}
    if ev.gpu:
        trainings |= gpu_trainings(paths)
    optima = Instances(paths.instances).optima()
    against = against_default(paths, summary)
    write_text(paths.report, report_text(s, summary, predict, trainings, optima, against))
    figures = save_figures(paths, summary)
    metrics = headline(summary, predict["networks"], planner.tau, describe())
    write_json(paths.headline, metrics)
    if logger.enabled:
        from vnrrt.studies.paper_comparison.runs import EvaluationFiles, log_evaluation

        files = EvaluationFiles(
            Path(paths.report), figures, Path(paths.trials_table), Path(paths.instances),
            sorted(Path(paths.heatmaps).glob("part_*.npz")), Path(paths.predict_metrics),
            Path(paths.ideas_summary), {n: Path(paths.train_metrics(n)) for n in trainings},
        )  # fmt: skip
        params = {"eval": dataclasses.asdict(ev), "planner": dataclasses.asdict(planner)}
        log_evaluation(logger, scale["name"], params, ev.sources, summary, metrics, files)
    return Path(paths.report)


def save_figures(paths: Paths, summary: dict) -> list[Path]:
    """Fig. 5 (paired improvement over RRT*) per stop rule that was run, and the
    convergence figure, under ``paths.evaluation_figures``; returns the files written."""
    import pandas as pd

    from vnrrt.data.instances import Instances
    from vnrrt.viz.evaluation import save_convergence, save_improvements

    figs = Path(paths.evaluation_figures)
    written = []
    eps, level = summary["eps"], summary["level"]
    for stop in summary["stops"]:
        if stop in summary["over_rrt_star"]["time_to_stop"]:
            path = figs / f"improvement_{stop}.png"
            save_improvements(
                path, summary["over_rrt_star"]["time_to_stop"][stop], stop, eps, level
            )
            written.append(path)
    curves = pd.read_csv(paths.convergence)
    if len(curves):
        save_convergence(figs / "convergence.png", curves, Instances(paths.instances).named())
        written.append(figs / "convergence.png")
    return written
