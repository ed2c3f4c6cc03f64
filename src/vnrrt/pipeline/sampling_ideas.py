"""Entry points of the sampling-ideas study's stages
(:mod:`vnrrt.studies.sampling_ideas.design` says what runs).

* ``oracle@<k>``: part ``k`` of the selection (every family member on the selection
  instances, in the protocol's cell and, with ``oracle.per_cell``, in every regime cell) ->
  ``paths.oracle_part(k)``;
* ``regime@<k>``: part ``k`` of the evaluation (the envelopes chosen from the merged selection,
  the networks, RRT*, in every regime cell, on the evaluation instances) ->
  ``paths.regime_part(k)``;
* ``ideas``: both merged (checked complete), their statistics (``paths.ideas_summary``),
  ``paths.ideas_report`` and its figures (``paths.ideas_figures``), and the MLflow run.
"""

from __future__ import annotations

import logging
from dataclasses import asdict, dataclass
from pathlib import Path

from omegaconf import DictConfig

from vnrrt.config import ConfigError, check_parts, conf_defaults, section, sections
from vnrrt.config.paths import Paths
from vnrrt.evaluation.config import Configurations, OracleConfig, RegimeConfig, RegimeGrid, Rules

log = logging.getLogger(__name__)


@dataclass
@conf_defaults("planner")
class StudyRules(Rules):
    """:class:`~vnrrt.evaluation.config.Rules` and the planner settings a regime cell
    overrides (``planner.eta``, ``radius_mode``, ``gamma_factor``, ``fixed_radius``,
    ``goal_radius``: their meaning in :class:`~vnrrt.planners.config.PlannerConfig`), for
    stage ``ideas``, which plans nothing: they say which grid cell is the protocol's own
    (:func:`~vnrrt.studies.sampling_ideas.design.protocol_settings`)."""

    eta: float
    radius_mode: str
    gamma_factor: float
    fixed_radius: float
    goal_radius: float | None


@dataclass(frozen=True)
class Study:
    """The typed sections the study's stages read (``regime`` is None in the selection);
    ``protocol``: the protocol cell's planner settings
    (:func:`~vnrrt.studies.sampling_ideas.design.protocol_settings`)."""

    paths: Paths
    ev: Configurations
    oracle: OracleConfig
    regime: RegimeConfig | None
    seed: int
    protocol: dict
    rules: Rules | None = None  # eps, max_iterations (the merged tables' checks), tau (M-VNRRT*)

    def design(self):
        """What the merged tables' rows must keep (:mod:`vnrrt.evaluation.invariants`)."""
        from vnrrt.data.instances import Instances
        from vnrrt.evaluation.invariants import design_of

        inst = Instances(self.paths.instances)
        return design_of(inst, self.rules.eps, self.rules.max_iterations, self.seed)

    def instances(self) -> tuple[list[str], list[int], list[int]]:
        """``(kinds, selection, evaluation)``: the instance kinds and the split (design)."""
        from vnrrt.data.instances import Instances
        from vnrrt.studies.sampling_ideas.design import split_instances

        inst = Instances(self.paths.instances)
        kinds, clusters = inst.kinds, inst.arrays["cluster"]
        chosen = [i for i, k in enumerate(kinds) if k == "random"][: self.oracle.random_maps]
        sel, ev = split_instances(chosen, [int(clusters[i]) for i in chosen],
                                  self.oracle.selection_share, self.seed)  # fmt: skip
        return kinds, sel, ev

    def selection_cells(self) -> dict:
        """``{label: planner overrides}`` of the cells the selection runs in (design)."""
        from vnrrt.studies.sampling_ideas.design import selection_cells

        return selection_cells(self.oracle, self.regime, self.protocol)

    def selection_jobs(self) -> list:
        """Every job of the selection (the protocol's cell first), in canonical order."""
        from vnrrt.evaluation.protocol import trial_jobs
        from vnrrt.studies.sampling_ideas.design import oracle_counts, selection_keys

        kinds, sel, _ = self.instances()
        keys, jobs = selection_keys(self.oracle, self.rules.tau), []
        for cell in self.selection_cells():
            seq = sum(j.count for j in jobs)
            jobs += trial_jobs(kinds, keys, oracle_counts(self.oracle, cell), regimes=(cell,),
                               instances=sel, seq=seq)  # fmt: skip
        return jobs

    def envelopes(self) -> tuple[dict, dict, dict]:
        """``(speed-ups, envelopes, own)`` of the merged selection: the protocol cell's, and
        each other cell's own envelopes
        (:func:`~vnrrt.studies.sampling_ideas.selection.by_cell`)."""
        from vnrrt.evaluation.table import merge_parts
        from vnrrt.studies.sampling_ideas.design import family_members
        from vnrrt.studies.sampling_ideas.selection import by_cell

        rows = sum(j.count for j in self.selection_jobs())
        table = merge_parts(self.paths.oracle, self.oracle.parts, rows, self.design())
        return by_cell(table, family_members(self.oracle, self.rules.tau))

    def evaluation_jobs(self, envelopes: dict, own: dict | None = None) -> list:
        """Every job of the evaluation (every cell, the protocol's first), canonical order;
        ``own``: each other cell's own envelopes, run there too."""
        from vnrrt.evaluation.protocol import trial_jobs
        from vnrrt.studies.sampling_ideas import design as d

        kinds, _, ev = self.instances()
        chosen, jobs = ev[: self.regime.random_maps], []
        every = d.evaluation_keys(envelopes, self.oracle, self.regime, self.ev, self.protocol,
                                  own)  # fmt: skip
        for cell, keys in every.items():
            counts = d.evaluation_counts(self.regime, cell)
            seq = sum(j.count for j in jobs)
            jobs += trial_jobs(kinds, keys, counts, regimes=(cell,), instances=chosen, seq=seq)
        return jobs


def part_settings(cfg: DictConfig, which: str) -> dict:
    """What stage ``oracle@<k>`` (``which='oracle'``) or ``regime@<k>`` reads, typed (keyed
    by config section); the evaluation also reads the trained networks' heatmaps
    (``predict.parts``)."""
    from vnrrt.planners.config import PlannerConfig
    from vnrrt.studies.sampling_ideas.design import protocol_settings

    typed = sections(cfg, paths=Paths, eval=Configurations, oracle=OracleConfig)
    typed |= sections(cfg, planner=PlannerConfig)
    typed["protocol"] = protocol_settings(typed["planner"])
    typed["regime"] = section(cfg, "regime", RegimeConfig if which == "regime" else RegimeGrid)
    if which == "regime":
        typed["predict"] = {"parts": check_parts(cfg.predict.parts, "predict.parts")}
        typed["train"] = {"seed": int(cfg.train.seed)}  # the networks' (the trials' network_seed)
    return typed | {"seed": int(cfg.seed), "workers": int(cfg.workers)}


def ideas_settings(cfg: DictConfig) -> dict:
    """What stage ``ideas`` reads, typed (keyed by config section; ``protocol``: the
    protocol cell's planner settings,
    :func:`~vnrrt.studies.sampling_ideas.design.protocol_settings`)."""
    from vnrrt.evaluation.config import StatsConfig
    from vnrrt.studies.sampling_ideas.design import protocol_settings
    from vnrrt.tracking.experiments import LoggerConfig

    typed = sections(cfg, paths=Paths, eval=Configurations, oracle=OracleConfig)
    typed |= sections(cfg, regime=RegimeConfig, planner=StudyRules, stats=StatsConfig)
    typed |= sections(cfg, logger=LoggerConfig)
    typed["protocol"] = protocol_settings(typed["planner"])
    return typed | {"scale": {"name": str(cfg.scale.name)}, "seed": int(cfg.seed)}


def _study(s: dict) -> Study:
    """The :class:`Study` of a stage's settings (:func:`part_settings`, :func:`ideas_settings`)."""
    return Study(s["paths"], s["eval"], s["oracle"], s["regime"], s["seed"], s["protocol"],
                 s["planner"])  # fmt: skip


def _run(s: dict, jobs: list, configs: dict, out: Path, networks: list[str], stage: str) -> int:
    """Run ``jobs`` (their instances read with the ``networks``' heatmaps) -> ``out``, reusing
    the kept rows of stage ``stage``'s unchanged configurations."""
    from vnrrt.data.instances import load
    from vnrrt.evaluation.table import with_network_seeds, write_table
    from vnrrt.evaluation.trials import TrialSettings, run_jobs

    st = _study(s)
    parts = s.get("predict", {}).get("parts", [0])
    indices = sorted({job.instance for job in jobs})
    instances, targets = load(st.paths.instances, indices, networks, st.paths.heatmaps, parts)
    oc, ev = st.oracle, st.ev
    heat = TrialSettings(oc.radius, ev.endpoint_radius, targets, None, oc.floor, ev.zero_obstacles,
                         ev.cap_factor)  # fmt: skip
    store = st.paths.reuse_store(stage)
    table = run_jobs(jobs, instances, s["seed"], s["workers"], configs, heat, store)
    seed = s.get("train", {}).get("seed", -1)
    write_table(with_network_seeds(table, dict.fromkeys(networks, seed)), out)
    return len(table)


def _part(jobs: list, part: int, parts: list[int], which: str) -> list:
    from vnrrt.evaluation.protocol import part_jobs

    if part not in parts:
        raise ConfigError(f"part {part} is not in {which}.parts {parts}")
    return part_jobs(jobs, part, len(parts))


def run_oracle_part(cfg: DictConfig, part: int) -> int:
    """Stage ``oracle@<part>`` (module doc): returns the number of trials."""
    s = part_settings(cfg, "oracle")
    st, planner = _study(s), s["planner"]
    jobs = _part(st.selection_jobs(), part, st.oracle.parts, "oracle")
    log.info("selection part %d/%d: %d jobs", part, len(st.oracle.parts), len(jobs))
    configs = {label: planner.replace(**o) for label, o in st.selection_cells().items()}
    return _run(s, jobs, configs, st.paths.oracle_part(part), [], "oracle")


def run_regime_part(cfg: DictConfig, part: int) -> int:
    """Stage ``regime@<part>`` (module doc): returns the number of trials."""
    from vnrrt.evaluation.sources import is_oracle
    from vnrrt.studies.sampling_ideas.design import PROTOCOL, regime_cells

    s = part_settings(cfg, "regime")
    st, planner = _study(s), s["planner"]
    _, envelopes, own = st.envelopes()
    jobs = _part(st.evaluation_jobs(envelopes, own), part, st.regime.parts, "regime")
    overrides = regime_cells(st.regime, st.protocol)
    cells = {label: planner.replace(**o) for label, o in overrides.items()}
    networks = sorted({j.key.source for j in jobs if j.key.source and not is_oracle(j.key.source)})
    log.info("evaluation part %d/%d: %d jobs", part, len(st.regime.parts), len(jobs))
    configs = {PROTOCOL: planner, **cells}
    return _run(s, jobs, configs, st.paths.regime_part(part), networks, "regime")


def ideas_tables(settings: dict) -> dict:
    """The selection's and the evaluation's trial parts merged (checked complete), with
    stage ``ideas``'s settings: ``{"oracle": table, "regime": table}``."""
    from vnrrt.evaluation.table import merge_parts

    st = _study(settings)
    _, envelopes, own = st.envelopes()
    rows = sum(j.count for j in st.selection_jobs())
    design = st.design()
    oracle = merge_parts(st.paths.oracle, st.oracle.parts, rows, design)
    rows = sum(j.count for j in st.evaluation_jobs(envelopes, own))
    regime = merge_parts(st.paths.regime, st.regime.parts, rows, design)
    return {"oracle": oracle, "regime": regime}


def ideas_summary(tables: dict, settings: dict, free: dict[int, int] | None = None) -> dict:
    """The study's statistics (:func:`~vnrrt.studies.sampling_ideas.summary.analyze_study`) of the
    merged ``tables`` with stage ``ideas``'s settings, which the summary records
    (``settings``), and each instance's free cells ``free`` (the distinct-cell rule)."""
    from vnrrt.infra.io import read_json
    from vnrrt.studies.paper_tables import claim_pairs, load_paper_tables
    from vnrrt.studies.sampling_ideas.summary import analyze_study, as_json

    st, rules, stats = _study(settings), settings["planner"], settings["stats"]
    pairs = claim_pairs(load_paper_tables(st.paths.paper_tables))
    shown = {"eps": rules.eps, "level": stats.level, "bootstrap": stats.bootstrap,
             "tail_draws": stats.tail_draws}  # fmt: skip
    shown |= {"radius": st.oracle.radius, "floor": st.oracle.floor}
    shown |= {"zero_obstacles": st.ev.zero_obstacles, "selection_share": st.oracle.selection_share}
    shown |= {"cap_factor": st.ev.cap_factor}
    predict = read_json(st.paths.predict_metrics)["networks"]
    study = {"oracle": st.oracle, "regime": st.regime, "ev": st.ev, "protocol": st.protocol,
             "targets": {n: m["target"] for n, m in predict.items()}, "tau": rules.tau}  # fmt: skip
    return as_json(analyze_study(tables, study, pairs, shown, free))


def ideas_text(summary: dict, settings: dict) -> str:
    """``sampling_ideas.md`` of the summary, its figures linked relative to the report."""
    import os

    from vnrrt.studies.sampling_ideas.report import build_ideas_report

    paths = settings["paths"]
    report = Path(paths.ideas_report)
    relative = [os.path.relpath(f, report.parent) for f in figure_files(paths, summary)]
    return build_ideas_report(summary, settings["scale"]["name"], relative)


def run_ideas(cfg: DictConfig) -> dict:
    """Stage ``ideas`` (module doc); returns the summary."""
    from vnrrt.data.instances import Instances
    from vnrrt.infra.io import read_json, write_json, write_text
    from vnrrt.tracking import store as tracking

    settings = ideas_settings(cfg)
    logger, paths = settings["logger"], settings["paths"]
    if logger.enabled:  # an unreachable store fails here, before any work
        tracking.check_store(tracking.tracking_uri(logger.uri))
    free = Instances(paths.instances).free_cells()
    write_json(paths.ideas_summary, ideas_summary(ideas_tables(settings), settings, free))
    summary = read_json(paths.ideas_summary)  # what every reader sees: the file's numbers
    written = save_figures(paths, summary)
    write_text(paths.ideas_report, ideas_text(summary, settings))
    if logger.enabled:
        from vnrrt.studies.sampling_ideas.runs import log_ideas

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
    curves, nets = pd.DataFrame(summary["curves"]), pd.DataFrame(summary["placed"])
    sweep = pd.DataFrame(summary["regime"])
    for path in written:
        if path.name == "quality_curve.png":
            save_quality(path, curves, nets, summary["settings"])
        else:
            save_regime(path, sweep, path.stem.removeprefix("regime_"), summary["settings"])
    return written
