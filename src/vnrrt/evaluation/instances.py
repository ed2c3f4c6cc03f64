"""Build the instances file (stage ``instances``; format in :mod:`vnrrt.data.instances`):
the named maps and ``R`` evaluation instances of the test split with their A* labels, exact
continuous optima (computed here, once per instance, over all cores) and taut A* lengths."""

from __future__ import annotations

import io
import json
from pathlib import Path

import numpy as np

from vnrrt.data.instances import FORMAT_VERSION, InstancesError
from vnrrt.data.reader import Shard
from vnrrt.data.splits import evaluation_keys
from vnrrt.infra.io import atomic_write_bytes
from vnrrt.infra.parallel import parallel_map
from vnrrt.planners.reference import taut_length
from vnrrt.search import any_angle_path


def _exact(args) -> tuple[np.ndarray, float, float]:
    grid, start, goal = args
    points, length = any_angle_path(grid, start, goal)
    return points, length, taut_length(grid, start, goal)


def _offsets(counts) -> np.ndarray:
    out = np.zeros(len(counts) + 1, np.int64)
    np.cumsum(counts, out=out[1:])
    return out


def _rows(shard: Shard, indices, keys, map_sets, names, clusters) -> list[dict]:
    rows = []
    o = shard.arrays["path_offsets"]
    for i, key, map_set, name, cluster in zip(indices, keys, map_sets, names, clusters):
        inst = shard.instance(int(i))
        rows.append(
            {
                "key": key,
                "map_set": map_set,
                "name": name,
                "cluster": cluster,
                "grid": shard.arrays["maps"][inst["map_index"]],
                "start": inst["start"],
                "goal": inst["goal"],
                "astar_length": inst["length"],
                "moves": shard.arrays["path_moves"][o[i] : o[i + 1]],
                "vertex_steps": shard.vertex_indices(int(i)).astype(np.uint32),
            }
        )
    return rows


def collect(
    named_maps: str | Path, shard_files: list[Path], shard_ids: list[int], n_random: int
) -> tuple[list[dict], dict]:
    """The protocol's instances as row dicts (packed grid, cells, A* label) and the meta."""
    named = Shard(named_maps)
    names = named.meta.get("names", [str(i) for i in range(named.n_instances)])
    n = named.n_instances
    rows = _rows(
        named,
        range(n),
        [(-1, i) for i in range(n)],
        [f"map_{i + 1}" for i in range(n)],
        names,
        [-1 - i for i in range(n)],
    )
    shards = [Shard(f) for f in shard_files]
    positions = evaluation_keys(shards, n_random) if n_random else np.zeros((0, 2), np.int64)
    if len(positions) < n_random:
        raise InstancesError(
            f"eval.random_maps={n_random} but the test split of shards "
            f"{shard_ids} holds only {len(positions)} instances"
        )
    for pos, i in positions:
        shard = shards[pos]
        map_id = shard.instance(int(i))["map_id"]
        rows += _rows(
            shard, [i], [(shard_ids[pos], int(i))], ["random"], [f"map{map_id}/inst{i}"], [map_id]
        )
    meta = {"map_size": named.size, "named": list(names), "shards": list(shard_ids)}
    return rows, meta


def build_instances(
    out: str | Path,
    named_maps: str | Path,
    shard_files: list[Path],
    shard_ids: list[int],
    n_random: int,
    workers: int = 0,
) -> dict:
    """Write the instances file (module doc) for the named maps and ``n_random`` test
    instances; the exact optima are computed over ``workers`` processes. Returns counts."""
    rows, meta = collect(named_maps, shard_files, shard_ids, n_random)
    size = meta["map_size"]
    grids = [np.unpackbits(r["grid"], axis=-1, count=size) for r in rows]
    centres = [(tuple(r["start"] + 0.5), tuple(r["goal"] + 0.5)) for r in rows]
    exact = parallel_map(
        _exact, [(g, s, e) for g, (s, e) in zip(grids, centres)], workers, "exact optima"
    )
    arrays = {
        "format_version": np.array(FORMAT_VERSION, np.int64),
        "meta": np.array(json.dumps(meta, sort_keys=True)),
        "keys": np.array([r["key"] for r in rows], np.int64).reshape(-1, 2),
        "map_set": np.array([r["map_set"] for r in rows]),
        "name": np.array([r["name"] for r in rows]),
        "cluster": np.array([r["cluster"] for r in rows], np.int64),
        "grids": np.stack([r["grid"] for r in rows]),
        "start": np.stack([r["start"] for r in rows]).astype(np.int64),
        "goal": np.stack([r["goal"] for r in rows]).astype(np.int64),
        "astar_length": np.array([r["astar_length"] for r in rows], np.float64),
        "exact_length": np.array([e[1] for e in exact], np.float64),
        "taut_length": np.array([e[2] for e in exact], np.float64),
        "path_offsets": _offsets([len(r["moves"]) for r in rows]),
        "path_moves": np.concatenate([r["moves"] for r in rows]).astype(np.uint8),
        "vertex_offsets": _offsets([len(r["vertex_steps"]) for r in rows]),
        "vertex_steps": np.concatenate([r["vertex_steps"] for r in rows]).astype(np.uint32),
        "exact_offsets": _offsets([len(e[0]) for e in exact]),
        "exact_points": np.concatenate([e[0] for e in exact]).reshape(-1, 2),
    }
    buf = io.BytesIO()
    np.savez_compressed(buf, **arrays)
    atomic_write_bytes(out, lambda f: f.write(buf.getvalue()))
    return {"instances": len(rows), "named": len(meta["named"]), "random": n_random}
