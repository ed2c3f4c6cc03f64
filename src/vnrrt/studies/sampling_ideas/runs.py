"""The MLflow run of the sampling-ideas study (stage ``ideas``): a parent run ``ideas
<scale>`` and one nested run per regime cell and configuration
(``<configuration> · <cell> · ideas <scale>``).

* The parent: the oracle and regime settings as params; the study's headline metrics (each
  idea's envelope against the path envelope, each network against its family's envelope:
  speed-up and CI bounds per stop rule and reading, :func:`headline_metrics`); the report
  (``sampling_ideas.md`` with its figures under the paths it uses, and ``.html``; its link to
  the paper comparison lists the evaluation runs built on this run), the summary, and the tag
  ``md5/ideas.json`` by which the evaluation run finds it (:mod:`vnrrt.tracking.lineage`).
* A nested run: params saying what it sampled (planner, tau, heatmap source, oracle kind,
  q, sigma, blend weight w, draw probability mix, obstacle rule, informed sampling, the
  regime cell); metrics per stop rule (success rate, median ms and iterations, heatmap mass
  near its target, speed-ups over RRT* with CI bounds:
  ``within_1pct_of_astar/speedup_over_rrt_star/iterations``).
"""

from __future__ import annotations

from pathlib import Path

from vnrrt.evaluation.keys import ConfigKey
from vnrrt.names import stop_slug
from vnrrt.tracking import experiments, lineage
from vnrrt.tracking import store as tracking

SPEEDUP = ("speedup", "ci_low", "ci_high")


def log_ideas(
    logger: experiments.LoggerConfig, scale: str, params: dict, summary: dict, artifacts: list[Path]
) -> str:
    """The parent run and its nested runs (module doc; ``params``: the settings to log,
    nested; ``artifacts``: the report (``.md``), the summary (``.json``) and the figures);
    returns the parent's id."""
    import mlflow

    uri, exp, tags = experiments.open_experiment(logger, "ideas", scale)
    client = tracking.open_store(uri)
    mlflow.set_tracking_uri(uri)
    files = [Path(p) for p in artifacts if Path(p).is_file()]
    extra = {}
    for path in (p for p in files if p.suffix == ".json"):
        extra |= lineage.content_tag(path.name, path)
    name = experiments.run_name(f"ideas {scale}")
    with mlflow.start_run(experiment_id=exp, run_name=name, tags=tags | extra) as run:
        mlflow.log_params(experiments.flat_params(params))
        mlflow.log_metrics(headline_metrics(summary))
        cells = dict.fromkeys((r["regime"], r["configuration"]) for r in summary["cells"])
        for cell, text in cells:
            log_configuration(exp, scale, tags, summary, cell, text)
        shown = log_files(client, exp, run.info.run_id, files)
        note = describe(exp, run.info.run_id, scale, shown)
        client.set_tag(run.info.run_id, "mlflow.note.content", note)
        return run.info.run_id


def describe(exp: str, run_id: str, scale: str, figures: list[str]) -> str:
    """The run's markdown description: what it is, where its report and the evaluation runs
    built on it are, and ``figures`` (the artifact paths of those the report shows)."""
    query = f"tags.ideas_run = '{run_id}'"
    lines = [
        f"**The sampling-ideas study at scale `{scale}`**: oracle heatmaps built from the "
        "labels, per idea and regime cell; one nested run per cell and configuration (params: "
        "oracle, q, sigma, w, mix, regime cell). The report: `sampling_ideas.html` (figures "
        f"inline) under Artifacts; [the evaluation runs built on it]"
        f"({lineage.search_link(exp, query)}).",
    ]
    for figure in figures:
        name = Path(figure).stem.replace("_", " ")
        lines += ["", f"![{name}]({lineage.artifact_url(run_id, figure)})"]
    return "\n".join(lines) + "\n"


def log_files(client, exp: str, run_id: str, files: list[Path]) -> list[str]:
    """The report with its figures and links
    (:func:`vnrrt.tracking.report_artifacts.log_report`), the other files at the
    artifact root; returns the artifact paths of the report's figures."""
    from vnrrt.tracking.report_artifacts import figure_paths, log_report

    query = f"tags.ideas_run = '{run_id}'"
    logged, shown = set(), []
    for report in (p for p in files if p.suffix == ".md"):
        links = {"paper_comparison.md": lineage.search_link(exp, query)}
        log_report(client, run_id, report, links)
        shown += figure_paths(report.read_text())
        logged |= {(report.parent / f).resolve() for f in figure_paths(report.read_text())}
    for path in files:
        if path.suffix != ".md" and path.resolve() not in logged:
            client.log_artifact(run_id, str(path))
    return shown


def log_configuration(exp: str, scale: str, tags: dict, summary: dict, cell: str,
                      text: str) -> None:  # fmt: skip
    """The nested run of configuration ``text`` in regime cell ``cell`` (module doc)."""
    import mlflow

    key = ConfigKey.parse(text)
    name = f"{key.label} · {cell} · ideas {scale}"
    run_tags = {**tags, "planner": text, "regime_cell": cell}
    with mlflow.start_run(experiment_id=exp, run_name=name, nested=True, tags=run_tags):
        mlflow.log_params(config_params(key, cell))
        mlflow.log_metrics(cell_metrics(summary, cell, text))


def config_params(key: ConfigKey, cell: str) -> dict[str, str]:
    """What a nested run sampled (module doc): ``null`` where it does not apply (the oracle
    fields of a network or uniform source, a default draw probability)."""
    from vnrrt.evaluation.oracles import OracleSource
    from vnrrt.evaluation.sources import is_oracle

    p = experiments.param_text
    oracle = OracleSource.parse(key.source) if is_oracle(key.source) else None
    return {
        "planner": key.planner,
        "tau": p(key.tau),
        "source": key.source or "uniform",
        "oracle": p(oracle and oracle.kind),
        "q": p(oracle and oracle.q),
        "sigma": p(oracle and oracle.sigma),
        "w": p(oracle and oracle.w),
        "mix": p(key.mix),
        "mask": key.mask or "raw",
        "free_cells_only": p(key.free),
        "informed": p(key.informed),
        "regime_cell": cell,
    }


def cell_metrics(summary: dict, cell: str, text: str) -> dict[str, float]:
    """Per stop rule, one configuration's success rate, median ms and iterations, heatmap
    masses and speed-ups over RRT* with CI bounds in regime cell ``cell``."""
    eps, out = summary["settings"]["eps"], {}
    for c in summary["cells"]:
        if (c["regime"], c["configuration"]) != (cell, text):
            continue
        keys = ("success_rate", "median_ms", "median_iterations", "heat_mass", "uniform_mass")
        vals: dict = {k: c.get(k) for k in keys}
        vals["speedup_over_rrt_star"] = {
            m: {s: c[m][s] for s in SPEEDUP} for m in ("iterations", "time_to_stop") if m in c
        }
        out.update(experiments.flat_metrics({stop_slug(c["stop"], eps): vals}))
    return out


def headline_metrics(summary: dict) -> dict[str, float]:
    """The study's headline numbers (module doc): ``<cell>/<stop>/<idea>_envelope_vs_path_
    envelope/<reading>/speedup`` (and ``ci_low``, ``ci_high``) and
    ``<stop>/<network configuration>_vs_<idea>_envelope/<reading>/...``."""
    eps, tree = summary["settings"]["eps"], {}
    for r in summary.get("envelopes", []):
        name = f"{r['idea']}_envelope_vs_{r['against']}_envelope"
        place = tree.setdefault(r["regime"], {}).setdefault(stop_slug(r["stop"], eps), {})
        place[name] = _readings(r)
    for r in summary.get("networks", []):
        name = f"{r['configuration']}_vs_{r['idea']}_envelope"
        tree.setdefault(stop_slug(r["stop"], eps), {})[name] = _readings(r)
    return experiments.flat_metrics(tree)


def _readings(row: dict) -> dict:
    return {m: {s: row[m][s] for s in SPEEDUP} for m in ("iterations", "time_to_stop") if m in row}
