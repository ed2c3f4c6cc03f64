"""The evaluation instances: the five named maps and ``R`` test-split instances, each with
the heatmaps of the trained networks (read from the ``predict`` stage's files).

Start and goal are the centres of the instance's cells, as in the paper; the reference
length is the instance's A* optimum (8-connected octile length between those cells).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from vnrrt.data.heatmaps import HeatmapError, read_heatmaps
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


def load_eval_instances(
    named_maps: str | Path,
    shards_dir: str | Path,
    shard_ids: list[int],
    heatmap_files: dict[str, str | Path],
    n_random: int,
) -> list[EvalInstance]:
    """Named maps (``map_1`` .. ``map_5``) then the first ``n_random`` evaluation instances
    of the test split (``random``), with heatmaps ``{source: (H, W) float32}``.

    ``heatmap_files`` maps a heatmap source name (``'path'``, ``'vertex'``) to a heatmap
    file of :mod:`vnrrt.data.heatmaps`; every file must cover the same test instances,
    keyed (shard id, instance index).
    """
    files = {src: read_heatmaps(path) for src, path in heatmap_files.items()}
    keys = None
    for src, arrays in files.items():
        if keys is None:
            keys = arrays["test_keys"]
        elif not np.array_equal(keys, arrays["test_keys"]):
            raise HeatmapError(f"heatmap file for '{src}' covers other test instances")
    named = Shard(named_maps)
    names = named.meta.get("names", [str(i) for i in range(named.n_instances)])
    out = []
    for i in range(named.n_instances):
        heat = {src: a["named"][i].astype(np.float32) for src, a in files.items()}
        out.append(_instance(named, i, f"map_{i + 1}", names[i], heat))
    keys = np.zeros((0, 2), np.int64) if keys is None else keys
    if n_random > len(keys):
        raise HeatmapError(f"{n_random} random instances asked, heatmaps cover {len(keys)}")
    shards: dict[int, Shard] = {}
    for row, (sid, i) in enumerate(keys[:n_random]):
        if int(sid) not in shard_ids:
            raise HeatmapError(f"heatmaps refer to shard {int(sid)}, not in {shard_ids}")
        shard = shards.setdefault(int(sid), Shard(shard_file(shards_dir, int(sid))))
        heat = {src: a["test"][row].astype(np.float32) for src, a in files.items()}
        map_id = shard.instance(int(i))["map_id"]
        out.append(_instance(shard, int(i), "random", f"map{map_id}/inst{int(i)}", heat))
    return out
