"""Entry point of the benchmark-maps study's stage (:mod:`vnrrt.studies.benchmark_maps`).

``bench_maps@benchmark_maps``: the queries sampled from the MovingAI maps of
``bench_maps.maps`` (``paths.movingai``), the trained networks' heatmaps of each (the map
padded to the encoder's stride and cropped back), the trials of RRT*, NRRT*, VNRRT*, M-VNRRT*
at ``planner.tau`` and the oracle envelopes the sampling-ideas study chose
(``paths.ideas_summary``) -> the trial table (``paths.bench_maps_trials``), the statistics
(``paths.bench_maps_summary``, beside the random-map speed-ups of ``paths.summary``), the
report (``paths.bench_maps_report``) and its MLflow run.
"""

from __future__ import annotations

import dataclasses
import logging
import time
from pathlib import Path

from omegaconf import DictConfig

from vnrrt.config import ConfigError, sections
from vnrrt.config.paths import Paths

log = logging.getLogger(__name__)


def bench_settings(cfg: DictConfig) -> dict:
    """What stage ``bench_maps@<name>`` reads, typed (keyed by config section)."""
    from vnrrt.evaluation.config import StatsConfig, check_cap_factor
    from vnrrt.planners.config import PlannerConfig
    from vnrrt.studies.benchmark_maps.config import BenchMapsConfig
    from vnrrt.tracking.experiments import LoggerConfig

    typed = sections(cfg, paths=Paths, planner=PlannerConfig, bench_maps=BenchMapsConfig)
    typed |= sections(cfg, stats=StatsConfig, logger=LoggerConfig)
    ev, oc = cfg.eval, cfg.oracle
    return typed | {
        "eval": {
            "sources": {str(k): str(v) for k, v in ev.sources.items()},
            "endpoint_radius": float(ev.endpoint_radius),
            "zero_obstacles": bool(ev.zero_obstacles),
            "cap_factor": check_cap_factor(ev.cap_factor),
        },
        "oracle": {"radius": float(oc.radius), "floor": float(oc.floor)},
        "labels": {"tie_break": str(cfg.labels.tie_break)},
        "predict": {"threads": int(cfg.predict.threads)},
        "scale": {"name": str(cfg.scale.name)},
        "seed": int(cfg.seed),
        "workers": int(cfg.workers),
    }


def bench_instances(s: dict) -> tuple[dict, dict]:
    """``({index: EvalInstance}, {map: facts})``: every sampled query of every map
    (:mod:`vnrrt.studies.benchmark_maps.design`), in map order, then bucket, then file line."""
    from vnrrt.studies.benchmark_maps.design import (
        build_instance,
        read_benchmark,
        sample_scenarios,
    )

    bm, out, maps = s["bench_maps"], {}, {}
    for map_id, (name, buckets) in enumerate(bm.maps.items()):
        grid, scenarios = read_benchmark(s["paths"].movingai, name)
        queries = sample_scenarios(scenarios, grid, name, buckets, bm.per_bucket, s["seed"])
        for q in queries:
            i = len(out)
            out[i] = build_instance(i, map_id, name, grid, q, s["labels"]["tie_break"])
        h, w = grid.shape
        maps[name] = {"width": w, "height": h, "buckets": list(buckets), "queries": len(queries)}
    return out, maps


def add_heatmaps(instances: dict, networks: list[str], paths: Paths) -> tuple[dict, dict]:
    """Each network's heatmap of every instance, the map padded to the encoder's stride
    (:func:`vnrrt.predict.heatmap`, ``pad=True``), added in place; returns each network's
    target (``'path'`` or ``'interior_vertices'``) and ``{map: {network: median ms}}``."""
    import numpy as np

    from vnrrt.predict import heatmap, load_model

    targets, ms = {}, {}
    for n in networks:
        model = load_model(paths.checkpoint(n))
        kind = model.record.get("target", {}).get("kind")
        targets[n] = "interior_vertices" if kind == "vertex" else "path"
        for i, inst in instances.items():
            tick = time.perf_counter()
            heat = heatmap(model, inst.grid, inst.start_cell, inst.goal_cell, pad=True)
            ms.setdefault(inst.map_set, {}).setdefault(n, []).append(
                1e3 * (time.perf_counter() - tick)
            )
            instances[i] = dataclasses.replace(inst, heatmaps={**inst.heatmaps, n: heat})
    return targets, {m: {n: float(np.median(v)) for n, v in d.items()} for m, d in ms.items()}


def bench_trials(s: dict, instances: dict, keys: list, targets: dict):
    """The trial table of ``keys`` on ``instances`` (reusing the kept rows of unchanged
    configurations, :mod:`vnrrt.evaluation.reuse`)."""
    from vnrrt.evaluation.trials import TrialSettings, run_jobs
    from vnrrt.studies.benchmark_maps.design import jobs

    ev, bm = s["eval"], s["bench_maps"]
    todo = jobs(len(instances), keys, bm.trials)
    log.info("benchmark maps: %d trial jobs on %d queries", len(todo), len(instances))
    heat = TrialSettings(
        s["oracle"]["radius"],
        ev["endpoint_radius"],
        targets,
        None,
        s["oracle"]["floor"],
        ev["zero_obstacles"],
        ev["cap_factor"],
    )
    store = s["paths"].reuse_store("bench_maps")
    return run_jobs(todo, instances, s["seed"], s["workers"], s["planner"], heat, store)


def summary_settings(s: dict) -> dict:
    """What the summary records of the run (its readers take every value from there)."""
    p, bm, st = s["planner"], s["bench_maps"], s["stats"]
    return {
        "eps": p.eps,
        "tau": p.tau,
        "max_iterations": p.max_iterations,
        "max_seconds": p.max_seconds,
        "level": st.level,
        "bootstrap": st.bootstrap,
        "seed": s["seed"],
        "trials": bm.trials,
        "per_bucket": bm.per_bucket,
    }


def run_bench_maps(cfg: DictConfig, name: str) -> dict:
    """Stage ``bench_maps@<name>`` (module doc); returns the summary."""
    import torch

    from vnrrt.evaluation.table import write_table
    from vnrrt.infra.io import read_json, write_json, write_text
    from vnrrt.studies.benchmark_maps.design import configurations, envelope_keys
    from vnrrt.studies.benchmark_maps.report import build_report
    from vnrrt.studies.benchmark_maps.summary import analyze

    s = bench_settings(cfg)
    paths, bm, logger = s["paths"], s["bench_maps"], s["logger"]
    if name not in bm.report:
        raise ConfigError(f"report {name!r} is not in bench_maps.report {bm.report}")
    _check_store(logger)
    torch.set_num_threads(s["predict"]["threads"])
    envelopes = envelope_keys(read_json(paths.ideas_summary).get("selection", {}), bm.ideas)
    keys = configurations(s["eval"]["sources"], s["planner"].tau, envelopes)
    instances, maps = bench_instances(s)
    networks = sorted({k.source for k in keys if k.source and not k.named_source})
    targets, inference = add_heatmaps(instances, networks, paths)
    for m in maps:
        maps[m]["inference_ms"] = inference.get(m, {})
    table = bench_trials(s, instances, keys, targets)
    write_table(table, paths.bench_maps_trials)
    texts = [k.text for k in keys]
    paper = read_json(paths.summary)
    summary = analyze(table, texts, envelopes, maps, summary_settings(s), paper)
    write_json(paths.bench_maps_summary, summary)
    summary = read_json(paths.bench_maps_summary)  # what every reader sees: the file's numbers
    write_text(paths.bench_maps_report, build_report(summary, s["scale"]["name"]))
    if logger.enabled:
        _log(s, summary)
    return summary


def _check_store(logger) -> None:
    """An unreachable tracking store fails here, before any work."""
    if logger.enabled:
        from vnrrt.tracking import store as tracking

        tracking.check_store(tracking.tracking_uri(logger.uri))


def _log(s: dict, summary: dict) -> str:
    """The study's MLflow run (:mod:`vnrrt.studies.benchmark_maps.runs`)."""
    from vnrrt.studies.benchmark_maps.runs import log_bench_maps

    paths, p = s["paths"], s["planner"]
    params = {
        "bench_maps": dataclasses.asdict(s["bench_maps"]),
        "planner": {
            "eps": p.eps,
            "tau": p.tau,
            "max_iterations": p.max_iterations,
            "max_seconds": p.max_seconds,
        },
    }
    files = [Path(paths.bench_maps_summary), Path(paths.bench_maps_trials)]
    return log_bench_maps(
        s["logger"], s["scale"]["name"], params, summary, Path(paths.bench_maps_report), files
    )
