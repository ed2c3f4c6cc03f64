"""The MLflow runs of the paper comparison (stage ``report``): a parent run ``evaluation
<scale>`` in the scale's experiment carrying the study's answer, and one nested run per
configuration (``<configuration> · evaluation <scale>``).

The parent holds:

* params: the evaluation and planner settings; metrics and tags of :mod:`.run_text` (the
  claims' speed-ups with CI bounds per reading, verdicts as tags, the headline numbers);
* a markdown description: the verdict table, links to the training runs, the registered
  model versions, the predict run and the ideas run, and Fig. 5;
* inputs: the logged models of the networks evaluated, the instances, the heatmap parts and
  the trial table as datasets with their DVC hashes (:mod:`vnrrt.tracking.lineage`);
* artifacts: ``paper_comparison.md`` (its link to ``sampling_ideas.md`` pointing at the ideas
  run's copy) and ``.html`` (:mod:`vnrrt.tracking.report_artifacts`), the figures under
  ``figures/evaluation/``, the trial table;
* tags naming the training runs, checkpoint hashes, predict and ideas runs it used.

A nested run's params are its configuration (planner, tau, heatmap source, mask variant,
draw probability, obstacle rule, informed sampling); its metrics, per map set and stop rule,
are success rate, median and mean time (ms) and median iterations
(``random_maps/within_1pct_of_astar/median_ms``).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from vnrrt.evaluation.keys import ConfigKey
from vnrrt.names import map_set_slug, stop_slug
from vnrrt.studies.paper_comparison import run_text
from vnrrt.tracking import experiments, lineage
from vnrrt.tracking import store as tracking


@dataclass(frozen=True)
class EvaluationFiles:
    """The files the evaluation run logs or links to."""

    report: Path  # paper_comparison.md
    figures: list[Path]  # the stage's figures (logged relative to the report's folder)
    trials: Path  # the merged trial table
    instances: Path
    heatmaps: list[Path]  # the heatmap parts
    predict: Path  # predict.json: finds the predict run
    ideas: Path  # ideas.json: finds the ideas run
    trainings: dict[str, Path]  # network -> its training metrics file


def log_evaluation(logger: experiments.LoggerConfig, scale: str, params: dict,
                   sources: dict[str, str], summary: dict, headline: dict,
                   files: EvaluationFiles) -> str:  # fmt: skip
    """The parent run and its nested runs (module doc; ``params``: the settings to log,
    nested; ``sources``: ``eval.sources``; ``headline``: ``headline.json``); returns the
    parent's id."""
    import mlflow

    uri, exp, tags = experiments.open_experiment(logger, "evaluation", scale)
    client = tracking.open_store(uri)
    trainings = [lineage.training_lineage(n, p) for n, p in sorted(files.trainings.items())]
    read = {"predict.json": files.predict, "ideas.json": files.ideas}
    found = {name: lineage.run_for_file(client, exp, name, path) for name, path in read.items()}
    used = {f"{n.removesuffix('.json')}_run": r.info.run_id for n, r in found.items() if r}
    own = training_tags(trainings) | run_text.claim_tags(summary["claims"]["rows"]) | used
    mlflow.set_tracking_uri(uri)
    name = experiments.run_name(f"evaluation {scale}")
    with mlflow.start_run(experiment_id=exp, run_name=name, tags=tags | own) as parent:
        run_id = parent.info.run_id
        mlflow.log_params(experiments.flat_params(params))
        mlflow.log_metrics(run_text.headline_metrics(summary, headline))
        for text in summary["keys"]:
            log_configuration(exp, scale, tags, text, sources, summary)
        ideas = found["ideas.json"]
        links = {} if ideas is None else {
            "sampling_ideas.md": lineage.artifact_link(exp, ideas.info.run_id, "sampling_ideas.md")
        }  # fmt: skip
        log_artifacts(client, run_id, files, links)
        inputs = {"instances": files.instances, "trials": files.trials}
        inputs |= {f"heatmaps {p.stem}": p for p in files.heatmaps}
        models = [t.model_id for t in trainings if t.model_id]
        lineage.log_datasets(client, run_id, inputs, "evaluation", models)
        figure = next((f for f in files.figures if f.name == "improvement_optimal.png"), None)
        url = lineage.artifact_url(run_id, _artifact_path(files, figure)) if figure else None
        text = run_text.describe(summary, scale, lineage_lines(exp, trainings, found), url)
        mlflow.set_tag("mlflow.note.content", text)
        return run_id


def log_configuration(exp: str, scale: str, tags: dict, text: str, sources: dict[str, str],
                      summary: dict) -> None:  # fmt: skip
    """The nested run of configuration ``text`` (module doc; ``tags``: the stage's, not the
    parent's lineage and verdicts)."""
    import mlflow

    key = ConfigKey.parse(text, sources)
    name = f"{key.label} · evaluation {scale}"
    with mlflow.start_run(experiment_id=exp, run_name=name, nested=True,
                          tags={**tags, "planner": text}):  # fmt: skip
        mlflow.log_params(config_params(key))
        mlflow.log_metrics(config_metrics(summary, text))


def _artifact_path(files: EvaluationFiles, figure: Path) -> str:
    """Where a figure of the stage is logged: its path relative to the report's folder."""
    import os

    return os.path.relpath(figure, files.report.parent)


def log_artifacts(client, run_id: str, files: EvaluationFiles, links: dict[str, str]) -> None:
    """The report (:func:`vnrrt.tracking.report_artifacts.log_report`), the stage's figures
    under their paths relative to the report and the trial table."""
    from vnrrt.tracking.report_artifacts import log_report

    log_report(client, run_id, files.report, links)
    for figure in files.figures:
        if figure.is_file():
            folder = str(Path(_artifact_path(files, figure)).parent)
            client.log_artifact(run_id, str(figure), None if folder == "." else folder)
    if files.trials.is_file():
        client.log_artifact(run_id, str(files.trials))


def training_tags(trainings: list[lineage.Training]) -> dict[str, str]:
    """Tags naming the training run and registry version of every network evaluated."""
    tags = {}
    for t in trainings:
        tags[f"training_run.{t.network}"] = t.run_id or "null"
        tags[f"model_version.{t.network}"] = t.model_version or "null"
    return tags


def lineage_lines(exp: str, trainings: list[lineage.Training], found: dict) -> list[str]:
    """The description's links: each network's training run and registry version, the
    predict run and the ideas run (those that exist)."""
    lines = lineage.training_links(exp, trainings)
    words = {"predict.json": "heatmap metrics and Fig. 3", "ideas.json": "the sampling-ideas study"}
    for name, run in found.items():
        if run is not None:
            link = lineage.run_link(exp, run.info.run_id)
            lines.append(f"- {words[name]}: [{run.info.run_name}]({link})")
    return ["Built on:", "", *lines] if lines else []


def config_params(key: ConfigKey) -> dict[str, str]:
    """The MLflow params of one configuration (module doc); ``null`` where it has none (a
    ``mix`` of ``null``: the parent's ``planner.mix``)."""
    p = experiments.param_text
    return {
        "planner": key.planner,
        "tau": p(key.tau),
        "source": key.source or "uniform",
        "mask": key.mask or "raw",
        "mix": p(key.mix),
        "free_cells_only": p(key.free),
        "informed": p(key.informed),
    }


def config_metrics(summary: dict, text: str) -> dict[str, float]:
    """Per map set and stop rule of one configuration: success rate, median and mean time
    (ms), median iterations (module doc)."""
    out, eps = {}, summary["eps"]
    for stop, per_key in summary["cells"].items():
        for map_set, m in per_key.get(text, {}).items():
            t, it = m["time_to_stop"], m["iterations"]
            vals = {
                "success_rate": t["success_rate"],
                "median_ms": None if t["median"] is None else 1e3 * t["median"],
                "mean_ms": None if t["mean"] is None else 1e3 * t["mean"],
                "median_iterations": it["median"],
            }
            place = {map_set_slug(map_set): {stop_slug(stop, eps): vals}}
            out.update(experiments.flat_metrics(place))
    return out
