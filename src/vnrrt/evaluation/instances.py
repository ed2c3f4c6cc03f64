"""The evaluation instances: the named maps and ``R`` test-split instances, each with the
heatmaps of the trained networks (read from the ``predict`` stages' files).

Instance ``i`` of the protocol is named map ``i`` for ``i < n_named`` (``map_1`` ..
``map_5``), else evaluation instance ``i - n_named`` of the test split (``random``), in the
order of the heatmap parts (:mod:`vnrrt.data.heatmaps`). Start and goal are the centres of
the instance's cells, as in the paper; the reference length is the instance's A* optimum
(8-connected octile length between those cells).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from vnrrt.data.heatmaps import HeatmapError, read_heatmaps, read_parts
from vnrrt.data.reader import Shard
from vnrrt.data.shards import shard_file
from vnrrt.evaluation.trials import EvalInstance


def _instance(shard: Shard, i: int, map_set: str, name: str, heatmaps: dict) -> EvalInstance:
    inst = shard.instance(i)
    return EvalInstance(
        map_set=map_set,
        map=name,
        grid=shard.grid(inst["map_index"]),
        start=tuple(float(v) + 0.5 for v in inst["start"]),
        goal=tuple(float(v) + 0.5 for v in inst["goal"]),
        reference_length=inst["length"],
        heatmaps=heatmaps,
    )


def instance_kinds(named_maps: str | Path, n_random: int) -> list[str]:
    """``'named'`` or ``'random'`` for every evaluation instance, in protocol order."""
    return ["named"] * Shard(named_maps).n_instances + ["random"] * n_random


def _sources(files: dict, sources: dict[str, str], where: str) -> dict[str, np.ndarray]:
    """``{source: (N, S, S)}`` from the networks of a heatmap file's ``maps``."""
    missing = sorted(n for n in sources.values() if n not in files["maps"])
    if missing:
        raise HeatmapError(f"heatmaps in {where} have no network {missing}")
    return {src: files["maps"][net] for src, net in sources.items()}


def load_eval_instances(
    named_maps: str | Path,
    shards_dir: str | Path,
    shard_ids: list[int],
    named_heatmaps: str | Path,
    heatmaps_dir: str | Path,
    parts: list[int],
    sources: dict[str, str],
    n_random: int,
    only: set[int] | None = None,
) -> dict[int, EvalInstance]:
    """``{protocol index: instance}`` for the indices in ``only`` (default: all), with
    heatmaps ``{source: (H, W) float32}``.

    ``sources`` maps a heatmap source name (``'path'``, ``'vertex'``) to the network whose
    heatmaps it is; they come from ``named_heatmaps`` and the ``<heatmaps_dir>/part_<k>.npz``
    files of ``parts``, keyed (shard id, instance index).
    """
    named = Shard(named_maps)
    n_named = named.n_instances
    wanted = set(range(n_named + n_random)) if only is None else set(only)
    out: dict[int, EvalInstance] = {}
    heat = {}
    if sources and any(i < n_named for i in wanted):
        heat = _sources(read_heatmaps(named_heatmaps), sources, named_heatmaps)
    names = named.meta.get("names", [str(i) for i in range(n_named)])
    for i in sorted(i for i in wanted if i < n_named):
        maps = {src: h[i].astype(np.float32) for src, h in heat.items()}
        out[i] = _instance(named, i, f"map_{i + 1}", names[i], maps)
    rows = sorted(i - n_named for i in wanted if i >= n_named)
    if not rows:
        return out
    files = read_parts(heatmaps_dir, parts)  # also with no sources: the evaluation keys
    keys, heat = files["keys"], _sources(files, sources, heatmaps_dir)
    if rows[-1] >= len(keys):
        raise HeatmapError(f"{n_random} random instances asked, heatmaps cover {len(keys)}")
    shards: dict[int, Shard] = {}
    for row in rows:
        sid, i = (int(v) for v in keys[row])
        if sid not in shard_ids:
            raise HeatmapError(f"heatmaps refer to shard {sid}, not in {shard_ids}")
        shard = shards.setdefault(sid, Shard(shard_file(shards_dir, sid)))
        maps = {src: h[row].astype(np.float32) for src, h in heat.items()}
        map_id = shard.instance(i)["map_id"]
        out[n_named + row] = _instance(shard, i, "random", f"map{map_id}/inst{i}", maps)
    return out
