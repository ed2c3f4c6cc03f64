"""Entry points of the sampling-ideas study's stages
(:mod:`vnrrt.evaluation.sampling_ideas.design` says what runs).

* ``oracle@<k>``: part ``k`` of the oracle study -> ``paths.oracle_part(k)``;
* ``regime@<k>``: part ``k`` of the planner-regime sweep -> ``paths.regime_part(k)``;
* ``ideas``: both merged (checked complete), their statistics (``paths.ideas_summary``),
  ``paths.ideas_report`` and its figures (``paths.ideas_figures``), and the MLflow run.
"""

from __future__ import annotations

import logging
from dataclasses import asdict, dataclass
from pathlib import Path

from omegaconf import DictConfig

from vnrrt.config import ConfigError, section, sections
from vnrrt.evaluation.config import Configurations, OracleConfig, RegimeConfig, mask_taus
from vnrrt.paths import Paths

log = logging.getLogger(__name__)


@dataclass(frozen=True)
class Study:
    """The typed sections the study's stages read: ``eval``'s configurations, ``oracle``,
    ``regime`` and the M-VNRRT* thresholds ``taus`` (``planner.taus`` and ``planner.tau``)."""

    paths: Paths
    sources: dict[str, str]  # eval.sources
    endpoint_radius: float  # eval.endpoint_radius (px)
    configurations: Configurations | None  # eval's; None where only the sweep runs
    oracle: OracleConfig
    regime: RegimeConfig | None  # None where only the oracle study runs
    taus: list[float]
    tau: float  # the claims' threshold (planner.tau)

    def design(self, which: str) -> tuple[list, dict, dict, list[int], int]:
        """``(keys, counts, cells, parts, instances)`` of the oracle study (``which=
        'oracle'``) or of the regime sweep; ``cells``: label -> planner overrides."""
        from vnrrt.evaluation.sampling_ideas import design as d

        if which == "oracle":
            o = self.oracle
            keys = d.oracle_keys(o, self.configurations, self.taus, self.tau)
            return keys, d.oracle_counts(o), {"": {}}, o.parts, o.random_maps
        r = self.regime
        keys = d.regime_keys(r, self.sources)
        return keys, d.regime_counts(), d.regime_cells(r), r.parts, r.random_maps

    def jobs(self, which: str) -> list:
        """Every job of the oracle study or the regime sweep, in canonical order."""
        from vnrrt.data.instances import Instances
        from vnrrt.evaluation.protocol import trial_jobs

        keys, counts, cells, _, n = self.design(which)
        kinds = Instances(self.paths.instances).kinds
        chosen = [i for i, k in enumerate(kinds) if k == "random"][:n]
        return trial_jobs(kinds, keys, counts, regimes=tuple(cells), instances=chosen)


def part_settings(cfg: DictConfig, which: str) -> dict:
    """What stage ``oracle@<k>`` (``which='oracle'``) or ``regime@<k>`` reads, typed (keyed
    by config section): the oracle study reads ``eval``'s configurations, the sweep
    ``eval.sources``; both the ``oracle`` section (the oracles' blur, floor and mass radius)
    and the whole ``planner``."""
    from vnrrt.config import check_parts
    from vnrrt.planners.config import PlannerConfig

    oracle_study = which == "oracle"
    return {
        "paths": section(cfg, "paths", Paths),
        "eval": section(cfg, "eval", Configurations)
        if oracle_study
        else {
            "sources": dict(cfg.eval.sources),
            "endpoint_radius": float(cfg.eval.endpoint_radius),
        },
        "oracle": section(cfg, "oracle", OracleConfig),
        "regime": None if oracle_study else section(cfg, "regime", RegimeConfig),
        "planner": section(cfg, "planner", PlannerConfig),
        "predict": {"parts": check_parts(cfg.predict.parts, "predict.parts")},
        "seed": int(cfg.seed),
        "workers": int(cfg.workers),
    }


def ideas_settings(cfg: DictConfig) -> dict:
    """What stage ``ideas`` reads, typed (keyed by config section)."""
    from vnrrt.evaluation.config import Rules, StatsConfig
    from vnrrt.tracking import LoggerConfig

    typed = sections(cfg, paths=Paths, eval=Configurations, oracle=OracleConfig)
    typed |= sections(cfg, regime=RegimeConfig, planner=Rules, stats=StatsConfig)
    return typed | sections(cfg, logger=LoggerConfig) | {"scale": {"name": str(cfg.scale.name)}}


def _study(s: dict) -> Study:
    """The :class:`Study` of a stage's settings (:func:`part_settings`,
    :func:`ideas_settings`)."""
    ev, planner = s["eval"], s["planner"]
    configurations = ev if isinstance(ev, Configurations) else None
    sources = ev.sources if configurations else ev["sources"]
    ends = ev.endpoint_radius if configurations else ev["endpoint_radius"]
    taus = mask_taus(planner.taus, planner.tau)
    regime = s["regime"]
    return Study(
        s["paths"], dict(sources), ends, configurations, s["oracle"], regime, taus, planner.tau
    )


def _run_part(cfg: DictConfig, part: int, which: str) -> int:
    """Part ``part`` of the oracle study or the regime sweep; returns the number of trials."""
    from vnrrt.data.instances import load
    from vnrrt.evaluation.protocol import part_jobs
    from vnrrt.evaluation.sources import is_oracle
    from vnrrt.evaluation.table import write_table
    from vnrrt.evaluation.trials import HeatSettings, run_jobs

    settings = part_settings(cfg, which)
    s, planner = _study(settings), settings["planner"]
    _, _, cells, parts, _ = s.design(which)
    if part not in parts:
        raise ConfigError(f"part {part} is not in {which}.parts {parts}")
    jobs = part_jobs(s.jobs(which), part, len(parts))
    networks = sorted({j.key.source for j in jobs if j.key.source and not is_oracle(j.key.source)})
    indices = sorted({job.instance for job in jobs})
    predict_parts = settings["predict"]["parts"]
    instances, targets = load(s.paths.instances, indices, networks, s.paths.heatmaps, predict_parts)
    heat = HeatSettings(s.oracle.radius, s.endpoint_radius, targets, s.oracle.sigma, s.oracle.floor)
    configs = {label: planner.replace(**over) for label, over in cells.items()}
    log.info(
        "%s part %d/%d: %d jobs on %d instances", which, part, len(parts), len(jobs), len(instances)
    )
    table = run_jobs(jobs, instances, settings["seed"], settings["workers"], configs, heat)
    out = s.paths.oracle_part(part) if which == "oracle" else s.paths.regime_part(part)
    write_table(table, out)
    return len(table)


def run_oracle_part(cfg: DictConfig, part: int) -> int:
    """Stage ``oracle@<part>`` (module doc)."""
    return _run_part(cfg, part, "oracle")


def run_regime_part(cfg: DictConfig, part: int) -> int:
    """Stage ``regime@<part>`` (module doc)."""
    return _run_part(cfg, part, "regime")


def ideas_tables(settings: dict) -> dict:
    """The oracle study's and the regime sweep's trial parts merged (checked complete), with
    stage ``ideas``'s settings: ``{"oracle": table, "regime": table}``."""
    from vnrrt.evaluation.table import merge_parts

    s, tables = _study(settings), {}
    for which in ("oracle", "regime"):
        folder = s.paths.oracle if which == "oracle" else s.paths.regime
        rows = sum(j.count for j in s.jobs(which))
        tables[which] = merge_parts(folder, s.design(which)[3], rows)
    return tables


def ideas_summary(tables: dict, settings: dict) -> dict:
    """The study's statistics (:func:`.summary.analyze_study`) of the merged ``tables``
    with stage ``ideas``'s settings, which the summary records (``settings``)."""
    from vnrrt.evaluation.paper_tables import claim_pairs, load_paper_tables
    from vnrrt.evaluation.protocol import configurations
    from vnrrt.evaluation.sampling_ideas.summary import analyze_study

    s, rules, st = _study(settings), settings["planner"], settings["stats"]
    networks = [k.text for k in configurations(s.configurations, s.taus, s.tau) if k.source]
    pairs = claim_pairs(load_paper_tables(s.paths.paper_tables))
    shown = {"eps": rules.eps, "level": st.level, "bootstrap": st.bootstrap}
    shown |= {"radius": s.oracle.radius, "sigma": s.oracle.sigma, "floor": s.oracle.floor}
    return analyze_study(tables["oracle"], tables["regime"], networks, pairs, shown)


def ideas_text(summary: dict, settings: dict) -> str:
    """``sampling_ideas.md`` of the summary, its figures linked relative to the report."""
    import os

    from vnrrt.evaluation.sampling_ideas.report import build_ideas_report

    paths = settings["paths"]
    report = Path(paths.ideas_report)
    relative = [os.path.relpath(f, report.parent) for f in figure_files(paths, summary)]
    return build_ideas_report(summary, settings["scale"]["name"], relative)


def run_ideas(cfg: DictConfig) -> dict:
    """Stage ``ideas`` (module doc); returns the summary."""
    from vnrrt import tracking
    from vnrrt.io import read_json, write_json, write_text

    settings = ideas_settings(cfg)
    logger, paths = settings["logger"], settings["paths"]
    if logger.enabled:  # an unreachable store fails here, before any work
        tracking.check_store(tracking.tracking_uri(logger.uri))
    write_json(paths.ideas_summary, ideas_summary(ideas_tables(settings), settings))
    summary = read_json(paths.ideas_summary)  # what every reader sees: the file's numbers
    written = save_figures(paths, summary)
    write_text(paths.ideas_report, ideas_text(summary, settings))
    if logger.enabled:
        from vnrrt.evaluation.sampling_ideas.runs import log_ideas

        params = {"oracle": asdict(settings["oracle"]), "regime": asdict(settings["regime"])}
        artifacts = [Path(paths.ideas_report), Path(paths.ideas_summary), *written]
        log_ideas(logger, settings["scale"]["name"], params, summary, artifacts)
    return summary


def figure_files(paths: Paths, summary: dict) -> list[Path]:
    """The figures :func:`save_figures` draws for ``summary``: the quality curve when the
    study has one, a regime figure per optimal stop rule of the sweep."""
    figs, out = Path(paths.ideas_figures), []
    if summary["curves"]:
        out.append(figs / "quality_curve.png")
    stops = {r["stop"] for r in summary["regime"]}
    out += [figs / f"regime_{s}.png" for s in ("optimal", "optimal_any_angle") if s in stops]
    return out


def save_figures(paths: Paths, summary: dict) -> list[Path]:
    """The quality curve and the regime figures under ``paths.ideas_figures``; returns the
    files written."""
    import pandas as pd

    from vnrrt.viz.ideas import save_quality, save_regime

    written = figure_files(paths, summary)
    curves, nets = pd.DataFrame(summary["curves"]), pd.DataFrame(summary["networks"])
    sweep = pd.DataFrame(summary["regime"])
    for path in written:
        if path.name == "quality_curve.png":
            save_quality(path, curves, nets, summary["settings"])
        else:
            stop = path.stem.removeprefix("regime_")
            save_regime(path, sweep, stop, summary["settings"])
    return written
