"""Build one shard: generate its base maps, label every start x goal pair, write the file.

A shard's bytes depend only on (seed, shard id, data/labels config, maps per shard):
each map draws from its own generator seeded by (seed, global map id), and the train/test
split of the shard's maps is a permutation seeded by (seed, shard id).
"""

from __future__ import annotations

import functools
import logging
from pathlib import Path

import numpy as np

from vnrrt.config import asdict
from vnrrt.data.config import LabelsConfig
from vnrrt.data.label import MapLabels, label_map
from vnrrt.data.reader import TEST, TRAIN
from vnrrt.data.shards import FORMAT_VERSION, meta_json, write_shard
from vnrrt.infra.parallel import parallel_map
from vnrrt.maps.config import DataConfig
from vnrrt.maps.generate import FloorMap, generate_map, map_rng

log = logging.getLogger(__name__)


def make_map(map_id: int, seed: int, data: DataConfig, labels: LabelsConfig):
    """Generate and label global map ``map_id``; returns ``(FloorMap, MapLabels)``."""
    fm = generate_map(map_rng(seed, map_id), data)
    return fm, label_map(fm, labels.vertex_steps, labels.tie_break, labels.tie_tolerance)


def split_of_maps(seed: int, shard_id: int, n_maps: int, train_fraction: float) -> np.ndarray:
    """``(n_maps,)`` uint8 split flags: ``round(n_maps * (1 - train_fraction))`` are TEST."""
    n_test = int(round(n_maps * (1.0 - train_fraction)))
    rng = np.random.default_rng(np.random.SeedSequence([seed, shard_id, 0x73706C]))
    split = np.full(n_maps, TRAIN, np.uint8)
    split[rng.permutation(n_maps)[:n_test]] = TEST
    return split


def _offsets(counts: np.ndarray) -> np.ndarray:
    out = np.zeros(len(counts) + 1, np.int64)
    np.cumsum(counts, out=out[1:])
    return out


def assemble(results: list[tuple[FloorMap, MapLabels]], map_ids: np.ndarray) -> dict:
    """Shard arrays (all but ``format_version``, ``meta``, ``split``) from per-map labels."""
    maps = [fm for fm, _ in results]
    labs = [lab for _, lab in results]
    inst_map = np.concatenate([np.full(len(lab.length), m, np.int32) for m, lab in enumerate(labs)])
    starts = np.stack([fm.starts for fm in maps]).astype(np.uint16)
    goals = np.stack([fm.goals for fm in maps]).astype(np.uint16)
    s_idx = np.concatenate([lab.start_index for lab in labs])
    g_idx = np.concatenate([lab.goal_index for lab in labs])
    return {
        "map_ids": np.asarray(map_ids, np.int64),
        "maps": np.stack([np.packbits(fm.grid.astype(bool), axis=-1) for fm in maps]),
        "starts": starts,
        "goals": goals,
        "inst_map": inst_map,
        "inst_start": starts[inst_map, s_idx],
        "inst_goal": goals[inst_map, g_idx],
        "inst_length": np.concatenate([lab.length for lab in labs]),
        "path_offsets": _offsets(np.concatenate([lab.n_moves for lab in labs])),
        "path_moves": np.concatenate([lab.moves for lab in labs]).astype(np.uint8),
        "vertex_offsets": _offsets(np.concatenate([lab.n_vertices for lab in labs])),
        "vertex_steps": np.concatenate([lab.vertex_steps for lab in labs]).astype(np.uint32),
    }


def write_labelled(
    out: str | Path, results: list, map_ids: np.ndarray, split: np.ndarray, **meta
) -> dict:
    """Assemble per-map ``(FloorMap, MapLabels)`` results into a shard file at ``out``."""
    arrays = assemble(results, map_ids)
    arrays["split"] = np.asarray(split, np.uint8)
    arrays["format_version"] = np.array(FORMAT_VERSION, np.int64)
    arrays["meta"] = meta_json(format_version=FORMAT_VERSION, **meta)
    write_shard(out, arrays)
    counts = {"maps": len(map_ids), "instances": len(arrays["inst_map"])}
    log.info("wrote %s: %d maps, %d instances", out, counts["maps"], counts["instances"])
    return counts


def build_shard(
    out: str | Path,
    shard_id: int,
    seed: int,
    maps_per_shard: int,
    data: DataConfig,
    labels: LabelsConfig,
    workers: int = 0,
) -> dict:
    """Generate and label shard ``shard_id`` and write it atomically to ``out``.

    Maps ``shard_id * maps_per_shard ...`` are built over a process pool of ``workers``
    (0 = all cores). Returns the counts of maps and instances written.
    """
    map_ids = shard_id * maps_per_shard + np.arange(maps_per_shard)
    job = functools.partial(make_map, seed=seed, data=data, labels=labels)
    results = parallel_map(job, [int(m) for m in map_ids], workers, f"shard {shard_id}")
    split = split_of_maps(seed, shard_id, maps_per_shard, data.train_fraction)
    return write_labelled(
        out, results, map_ids, split, seed=seed, shard=shard_id, maps_per_shard=maps_per_shard,
        map_size=data.size, data=asdict(data), labels=asdict(labels),
    )  # fmt: skip
