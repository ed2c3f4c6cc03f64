"""The MLflow run of the benchmark-maps study (stage ``bench_maps@benchmark_maps``): one run
``bench_maps <scale>`` of kind ``bench_maps``.

* Params: the ``bench_maps`` section and the planner budgets and stop tolerance it ran with.
* Metrics (:func:`headline_metrics`): per map (and ``pooled``) and configuration, the solve
  rate, median ms and the speed-ups over RRT* with CI bounds,
  ``<map>/within_1pct_of_exact_optimum/<configuration>/speedup_over_rrt_star/time_to_stop/
  speedup``; each network against its envelope (``.../<configuration>_vs_<idea>_envelope/...``).
  A configuration is named by its short key (``vnrrt``, ``m0.5``) or ``<idea>_envelope``.
* The description: the pooled speed-ups, the out-of-distribution table and what the
  intervals support (:func:`~vnrrt.studies.benchmark_maps.report.description`); the report
  as artifacts (``benchmark_maps.md`` and ``.html``), the summary and the trial table; the
  tag ``md5/<summary file>`` finds the run by its file (:mod:`vnrrt.tracking.lineage`).
"""

from __future__ import annotations

from pathlib import Path

from vnrrt.evaluation.keys import ConfigKey
from vnrrt.names import stop_slug
from vnrrt.studies.benchmark_maps.design import STOP
from vnrrt.tracking import experiments, lineage
from vnrrt.tracking import store as tracking

READ = ("speedup", "ci_low", "ci_high")
KIND = "bench_maps"


def short_names(summary: dict) -> dict[str, str]:
    """``{key text: metric name part}``: ``<idea>_envelope`` or the key's short form."""
    envelopes = {text: f"{idea}_envelope" for idea, text in summary["envelopes"].items()}
    return {k: envelopes.get(k, ConfigKey.parse(k).short) for k in summary["keys"]}


def headline_metrics(summary: dict) -> dict[str, float]:
    """The study's metrics (module doc), finite values only."""
    short, tree = short_names(summary), {}
    stop = stop_slug(STOP, summary["settings"]["eps"])
    for c in summary["cells"]:
        vals: dict = {k: c[k] for k in ("solve_rate", "median_ms", "median_iterations")}
        vals["speedup_over_rrt_star"] = {
            m: {r: c[m][r] for r in READ} for m in ("time_to_stop", "iterations") if m in c
        }
        tree.setdefault(c["map"], {}).setdefault(stop, {})[short[c["configuration"]]] = vals
    for r in summary["against_envelopes"]:
        name = f"{short[r['configuration']]}_vs_{r['idea']}_envelope"
        tree.setdefault(r["map"], {}).setdefault(stop, {})[name] = {
            m: {k: r[m][k] for k in READ} for m in ("time_to_stop", "iterations")
        }
    return experiments.flat_metrics(tree)


def log_bench_maps(
    logger: experiments.LoggerConfig,
    scale: str,
    params: dict,
    summary: dict,
    report: Path,
    files: list[Path],
) -> str:
    """The study's run (module doc; ``params``: the settings to log, nested; ``report``: the
    markdown report; ``files``: the summary and trial table); returns its id."""
    import mlflow

    from vnrrt.studies.benchmark_maps.report import description
    from vnrrt.tracking.report_artifacts import log_report

    uri, exp, tags = experiments.open_experiment(logger, KIND, scale)
    client = tracking.open_store(uri)
    mlflow.set_tracking_uri(uri)
    extra = {}
    for path in (Path(p) for p in files if Path(p).suffix == ".json"):
        extra |= lineage.content_tag(path.name, path)
    name = experiments.run_name(f"bench_maps {scale}")
    with mlflow.start_run(experiment_id=exp, run_name=name, tags=tags | extra) as run:
        mlflow.log_params(experiments.flat_params(params))
        mlflow.log_metrics(headline_metrics(summary))
        log_report(client, run.info.run_id, Path(report))
        for path in files:
            client.log_artifact(run.info.run_id, str(path))
        client.set_tag(run.info.run_id, "mlflow.note.content", description(summary, scale))
        return run.info.run_id
