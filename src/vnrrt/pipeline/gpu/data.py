"""Shards for a GPU run, made on the machine's cores with the project's data code.

Shards ``0, 1, ...`` of the bundle's seed and ``maps_per_shard`` are the pipeline's shards of
the same ids (a map depends only on (seed, map id) and the data config), so the instances
file's test maps come out again here, again in the test split. :func:`check_heldout` proves
that no evaluation instance's map is among the maps trained on.
"""

from __future__ import annotations

import functools
import logging
import math
import time
from pathlib import Path

import numpy as np

from vnrrt.data.build import build_shard, make_map
from vnrrt.data.config import LabelsConfig
from vnrrt.data.manifest import build_manifest
from vnrrt.data.reader import TRAIN, Shard
from vnrrt.data.shards import shard_file
from vnrrt.infra.parallel import n_workers, parallel_map
from vnrrt.maps.config import DataConfig

log = logging.getLogger(__name__)


def data_configs(cfg: dict) -> tuple[DataConfig, LabelsConfig]:
    """The bundle's ``data`` and ``labels`` sections, validated."""
    data, labels = DataConfig(**cfg["data"]), LabelsConfig(**cfg["labels"])
    data.validate()
    labels.validate()
    return data, labels


def _one_shard(shard_id: int, shards_dir: Path, cfg: dict) -> dict:
    data, labels = data_configs(cfg)
    out = shard_file(shards_dir, shard_id)
    return build_shard(out, shard_id, cfg["seed"], cfg["maps_per_shard"], data, labels, 1)


def warm_up(cfg: dict) -> float:
    """Label one map here (compiles the numba kernels, which forked workers then share);
    returns its seconds."""
    tick = time.perf_counter()
    make_map(0, cfg["seed"], *data_configs(cfg))
    return time.perf_counter() - tick


def build_round(shards_dir: Path, ids: list[int], cfg: dict, cores: int) -> list[dict]:
    """Build shards ``ids`` over ``cores`` processes (one shard each at a time)."""
    job = functools.partial(_one_shard, shards_dir=shards_dir, cfg=cfg)
    return parallel_map(job, ids, cores, f"shards {ids[0]}..{ids[-1]}")


def train_per_shard(cfg: dict, counts: list[dict]) -> float:
    """Expected training instances per shard (train maps less the validation share)."""
    mean = float(np.mean([c["instances"] for c in counts]))
    return mean * cfg["data"]["train_fraction"] * (1.0 - cfg["datamodule"]["val_fraction"])


def shards_wanted(images: float, per_shard: float, max_shards: int) -> int:
    """Shards whose training instances cover ``images`` once (1..``max_shards``)."""
    return int(min(max_shards, max(1, math.ceil(images / max(per_shard, 1.0)))))


def more_rounds(shards_dir: Path, cfg: dict, have: int, want: int, cores: int,
                seconds_left: float, round_s: float) -> int:  # fmt: skip
    """Build rounds of ``cores`` shards after the first ``have`` until ``want`` shards exist
    or the next round (``round_s`` seconds, as the last one took) would pass
    ``seconds_left``; returns the number of shards."""
    size = n_workers(cores)
    deadline = time.perf_counter() + seconds_left
    while have < want and time.perf_counter() + round_s <= deadline:
        tick = time.perf_counter()
        build_round(shards_dir, list(range(have, min(want, have + size))), cfg, cores)
        have, round_s = min(want, have + size), time.perf_counter() - tick
    log.info("%d shards (%d wanted)", have, want)
    return have


def manifest(shards_dir: Path, n: int, out: Path) -> dict:
    """The manifest of shards ``0..n-1`` (the data module checks shards against it)."""
    return build_manifest(shards_dir, list(range(n)), out)


def check_heldout(instances, shard_files: list[Path]) -> dict[str, int]:
    """Match the instances' base maps (``cluster``) with the maps of ``shard_files``.

    Returns counts: ``regenerated`` (same map id and grid: held out in the test split),
    ``differ`` (same id, another grid: the instances come from other data settings, so no
    map is shared). Raises ``ValueError`` if an instance's map is a training map here.
    """
    maps: dict[int, tuple[Shard, int]] = {}
    for f in shard_files:
        shard = Shard(f)
        maps.update({int(m): (shard, j) for j, m in enumerate(shard.arrays["map_ids"])})
    counts = {"regenerated": 0, "differ": 0}
    a = instances.arrays
    for i, cluster in enumerate(a["cluster"]):
        if int(cluster) not in maps:
            continue
        shard, j = maps[int(cluster)]
        if not np.array_equal(shard.arrays["maps"][j], a["grids"][i]):
            counts["differ"] += 1
        elif shard.arrays["split"][j] == TRAIN:
            name = a["name"][i]
            raise ValueError(f"evaluation instance {i} ({name}) lies on map {int(cluster)}, "
                             "a training map here: the heldout check fails")  # fmt: skip
        else:
            counts["regenerated"] += 1
    return counts
