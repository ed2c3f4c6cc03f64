"""Entry points of the data stages (``shard@<id>``, ``named_maps``, ``manifest``):
parameters in, typed arguments out, one call each. Each receives the parameters its
``dvc.yaml`` entry declares (:func:`vnrrt.config.restrict`)."""

from __future__ import annotations

import logging

from omegaconf import DictConfig

from vnrrt.config import ConfigError, section
from vnrrt.config.paths import Paths
from vnrrt.data.config import LabelsConfig

log = logging.getLogger(__name__)


def run_shard(cfg: DictConfig, shard_id: int) -> dict:
    """Stage ``shard@<id>``: generate and label one shard into ``paths.shards``."""
    from vnrrt.data.build import build_shard
    from vnrrt.maps.config import DataConfig

    if shard_id not in cfg.scale.shards:
        raise ConfigError(f"shard {shard_id} is not in scale.shards {list(cfg.scale.shards)}")
    return build_shard(
        section(cfg, "paths", Paths).shard(shard_id),
        shard_id,
        seed=int(cfg.seed),
        maps_per_shard=int(cfg.scale.maps_per_shard),
        data=section(cfg, "data", DataConfig),
        labels=section(cfg, "labels", LabelsConfig),
        workers=int(cfg.workers),
    )


def run_named_maps(cfg: DictConfig) -> dict:
    """Stage ``named_maps``: the five named maps as a shard, and their figure (Fig. 4)."""
    from vnrrt.data.build_named import build_named_maps
    from vnrrt.data.reader import Shard
    from vnrrt.viz.maps import save_named_maps

    paths, labels = section(cfg, "paths", Paths), section(cfg, "labels", LabelsConfig)
    counts = build_named_maps(paths.named_maps, int(cfg.data.size), labels)
    save_named_maps(Shard(paths.named_maps), paths.named_maps_figure)
    return counts


def run_manifest(cfg: DictConfig) -> dict:
    """Stage ``manifest``: checksums and counts of all shards, and the data metrics."""
    from vnrrt.data.manifest import build_manifest
    from vnrrt.infra.io import write_json

    paths = section(cfg, "paths", Paths)
    shards = [int(s) for s in cfg.scale.shards]
    summary = build_manifest(paths.shards, shards, paths.manifest)
    write_json(paths.data_metrics, summary)
    return summary
