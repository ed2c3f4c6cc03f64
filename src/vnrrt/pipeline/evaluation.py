"""Entry points of the evaluation engine's stages: ``instances`` (the protocol's instances with
their reference lengths) and ``trials@<k>`` (part ``k`` of the protocol's trials). The two
studies have their own: :mod:`vnrrt.pipeline.paper_comparison` (``evaluate``,
``report``) and :mod:`vnrrt.pipeline.sampling_ideas` (``oracle@<k>``, ``regime@<k>``,
``ideas``).

Each entry receives the parameters its ``dvc.yaml`` entry declares
(:func:`vnrrt.config.restrict`); its ``*_settings`` function turns them into typed sections
(keyed by config section, so that a test can check every key reaches its stage), and the
entry calls typed functions below with them. Heavy imports stay inside the functions, so a
stage's code dependencies are what it runs.
"""

from __future__ import annotations

import logging

from omegaconf import DictConfig

from vnrrt.config import ConfigError, check_parts, section, sections
from vnrrt.config.paths import Paths

log = logging.getLogger(__name__)


def instances_settings(cfg: DictConfig) -> dict:
    """What stage ``instances`` reads, typed."""
    return {
        "paths": section(cfg, "paths", Paths),
        "scale": {"shards": [int(s) for s in cfg.scale.shards]},
        "eval": {"random_maps": int(cfg.eval.random_maps)},
        "workers": int(cfg.workers),
    }


def run_instances(cfg: DictConfig) -> dict:
    """Stage ``instances``: named maps and ``eval.random_maps`` test instances with their
    A* and exact optima -> ``paths.instances``."""
    from vnrrt.data.manifest import verified_files
    from vnrrt.evaluation.instances import build_instances

    s = instances_settings(cfg)
    paths, shards = s["paths"], s["scale"]["shards"]
    files = verified_files(paths.shards, paths.manifest, shards)
    n = s["eval"]["random_maps"]
    return build_instances(paths.instances, paths.named_maps, files, shards, n, s["workers"])


def trials_settings(cfg: DictConfig) -> dict:
    """What stage ``trials@<k>`` reads, typed."""
    from vnrrt.evaluation.config import EvalConfig
    from vnrrt.planners.config import PlannerConfig

    return sections(cfg, paths=Paths, eval=EvalConfig, planner=PlannerConfig) | {
        "oracle": {"radius": float(cfg.oracle.radius)},
        "predict": {"parts": check_parts(cfg.predict.parts, "predict.parts")},
        "train": {"seed": int(cfg.train.seed)},  # the networks' (the trials' network_seed)
        "seed": int(cfg.seed),
        "workers": int(cfg.workers),
    }


def add_gpu_heatmaps(instances: dict, paths: Paths) -> dict[str, str]:
    """Add the GPU-trained paper networks' heatmaps (``paths.gpu_returned``, read and
    checked against ``paths.instances`` by :func:`vnrrt.data.returned.read_returned`) to
    ``instances`` ``{index: EvalInstance}`` in place; returns each network's target."""
    import dataclasses

    import numpy as np

    from vnrrt.data.returned import NETWORKS, read_returned

    got = read_returned(paths.gpu_returned, paths.instances)
    for i, inst in instances.items():
        heat = {n: m[i].astype(np.float32) for n, m in got["maps"].items()}
        instances[i] = dataclasses.replace(inst, heatmaps={**inst.heatmaps, **heat})
    kinds = {n: got["meta"][0]["networks"][n]["target"]["kind"] for n in NETWORKS}
    return {n: "interior_vertices" if k == "vertex" else "path" for n, k in kinds.items()}


def run_trials_part(cfg: DictConfig, part: int) -> int:
    """Stage ``trials@<part>``: the trials of part ``part`` of ``eval.parts`` ->
    ``paths.trials_part(part)``; returns the number of trials."""
    from vnrrt.data.instances import Instances, load
    from vnrrt.evaluation.config import mask_taus
    from vnrrt.evaluation.protocol import (
        GPU_SOURCES,
        configurations,
        part_jobs,
        trial_counts,
        trial_jobs,
    )
    from vnrrt.evaluation.table import with_network_seeds, write_table
    from vnrrt.evaluation.trials import TrialSettings, run_jobs

    s = trials_settings(cfg)
    paths, ev, planner = s["paths"], s["eval"], s["planner"]
    if part not in ev.parts:
        raise ConfigError(f"part {part} is not in eval.parts {ev.parts}")
    keys = configurations(ev, mask_taus(planner.taus, planner.tau), planner.tau)
    jobs = trial_jobs(Instances(paths.instances).kinds, keys, trial_counts(ev))
    jobs = part_jobs(jobs, part, len(ev.parts))
    networks = sorted({k.source for k in keys if k.source is not None})
    indices = sorted({job.instance for job in jobs})
    parts = s["predict"]["parts"]
    trained = [n for n in networks if n not in GPU_SOURCES.values()]
    instances, targets = load(paths.instances, indices, trained, paths.heatmaps, parts)
    if len(trained) < len(networks):
        targets |= add_gpu_heatmaps(instances, paths)
    log.info(
        "part %d/%d: %d trial jobs on %d instances", part, len(ev.parts), len(jobs), len(instances)
    )
    heat = TrialSettings(s["oracle"]["radius"], ev.endpoint_radius, targets,
                         zero_obstacles=ev.zero_obstacles, cap_factor=ev.cap_factor)  # fmt: skip
    store = paths.reuse_store("trials")
    table = run_jobs(jobs, instances, s["seed"], s["workers"], planner, heat, store,
                     ev.timing_noise)  # fmt: skip
    table = with_network_seeds(table, dict.fromkeys(trained, s["train"]["seed"]))
    write_table(table, paths.trials_part(part))
    return len(table)
