"""Entry points of the DVC stages: each takes the composed parameters (``params.yaml``),
picks and validates the sections it needs, and calls one computation.

Paths come from the ``paths`` config group only. Stage scripts under ``stages/`` are thin
wrappers around these functions (:func:`vnrrt.stage_cli.stage_main`). The stages with parts
(``shard@<id>``, ``predict@<k>``, ``trials@<k>``) are also the shard jobs of
:mod:`vnrrt.multirun` (:data:`PART_STAGES`).
"""

from __future__ import annotations

import logging
from collections.abc import Callable

from omegaconf import DictConfig

from vnrrt.config import DataConfig, LabelsConfig, ScaleConfig, section
from vnrrt.data.build import build_named_maps, build_shard
from vnrrt.data.manifest import build_manifest, write_json
from vnrrt.data.shards import shard_file

log = logging.getLogger(__name__)


def run_shard(cfg: DictConfig, shard_id: int) -> dict:
    """Stage ``shard@<id>``: generate and label one shard into ``paths.shards``."""
    scale = section(cfg, "scale", ScaleConfig)
    if shard_id not in scale.shards:
        log.warning("shard %d is not in scale.shards %s", shard_id, scale.shards)
    return build_shard(
        shard_file(cfg.paths.shards, shard_id),
        shard_id,
        seed=int(cfg.seed),
        maps_per_shard=scale.maps_per_shard,
        data=section(cfg, "data", DataConfig),
        labels=section(cfg, "labels", LabelsConfig),
        workers=int(cfg.get("workers", 0)),
    )


def run_named_maps(cfg: DictConfig) -> dict:
    """Stage ``named_maps``: the five named maps as a shard, and their figure (Fig. 4)."""
    from vnrrt import viz  # matplotlib only where figures are drawn

    data = section(cfg, "data", DataConfig)
    counts = build_named_maps(cfg.paths.named_maps, data.size, section(cfg, "labels", LabelsConfig))
    viz.save_named_maps(cfg.paths.named_maps, f"{cfg.paths.figures}/named_maps.png")
    return counts


def run_manifest(cfg: DictConfig) -> dict:
    """Stage ``manifest``: checksums and counts of all shards, and the data metrics."""
    scale = section(cfg, "scale", ScaleConfig)
    summary = build_manifest(cfg.paths.shards, scale.shards, cfg.paths.manifest)
    write_json(f"{cfg.paths.metrics}/data.json", summary)
    return summary


def run_train(cfg: DictConfig, network: str) -> dict:
    """Stage ``train_<network>``: train VertexNet (``vertexnet``) or the NRRT* network
    (``nrrtnet``) into ``paths.models`` and log the run to MLflow (:mod:`vnrrt.train`)."""
    from vnrrt import tracking

    tracking.configure(cfg.logger.uri)  # before Lightning (and its MLflow logger) is imported
    from vnrrt.train import train

    return train(cfg, network)


def run_predict_part(cfg: DictConfig, part: int) -> dict:
    """Stage ``predict@<part>``: heatmaps of the trained networks for part ``part`` of the
    evaluation instances (:func:`vnrrt.predict.predict_part`)."""
    from vnrrt.predict import predict_part

    return predict_part(cfg, part)


def run_predict_named(cfg: DictConfig) -> dict:
    """Stage ``predict_named``: heatmaps of the named maps, the prediction metrics over all
    parts (``predict.json``) and the paper's Fig. 3 on the named maps."""
    from vnrrt import viz
    from vnrrt.data.heatmaps import read_heatmaps
    from vnrrt.data.reader import Shard
    from vnrrt.predict import predict_named

    results = predict_named(cfg)
    write_json(f"{cfg.paths.metrics}/predict.json", results)
    named = Shard(cfg.paths.named_maps)
    ids = named.instances()
    maps = read_heatmaps(cfg.paths.named_heatmaps)["maps"]
    viz.save_heatmaps(
        f"{cfg.paths.figures}/heatmaps.png",
        [named.grid(named.instance(i)["map_index"]) for i in ids],
        [named.path(i) for i in ids], [named.vertices(i) for i in ids], maps,
        titles=named.meta.get("names"),
    )  # fmt: skip
    return results


def run_trials_part(cfg: DictConfig, part: int) -> int:
    """Stage ``trials@<part>``: part ``part`` of the evaluation trials
    (:func:`vnrrt.evaluation.stage.run_trials_part`)."""
    from vnrrt.evaluation.stage import run_trials_part as run

    return run(cfg, part)


# Stages with parts: name -> (entry point taking (cfg, part id), config key of the part ids).
PART_STAGES: dict[str, tuple[Callable[[DictConfig, int], object], str]] = {
    "shard": (run_shard, "scale.shards"),
    "predict": (run_predict_part, "predict.parts"),
    "trials": (run_trials_part, "eval.parts"),
}
