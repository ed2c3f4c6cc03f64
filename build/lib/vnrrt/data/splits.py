"""How instances are split and chosen (no torch here, so that data and evaluation stages do
not import it).

Splits are by base map, so no map lends instances to two splits: the shards' test maps are the
``test`` split; of each shard's train maps a seeded ``val_fraction`` (by ``(seed, shard id)``)
form ``val``, the rest ``train``. Instances are keyed ``(shard position, instance index)`` in
shard order; limits keep evenly spaced keys (spread over many maps, no RNG).
"""

from __future__ import annotations

import numpy as np

from vnrrt.data.reader import TRAIN, Shard

SPLIT_NAMES = ("train", "val", "test")


def evenly_spaced(keys: np.ndarray, n: int | None) -> np.ndarray:
    """At most ``n`` rows of ``keys`` ``(N, 2)`` at evenly spaced positions (all if ``n`` is
    None or >= N), in their original order."""
    if n is None or n >= len(keys):
        return keys
    if n < 0:
        raise ValueError(f"an instance limit must be >= 0, got {n}")
    return keys[np.unique(np.linspace(0, len(keys) - 1, n).round().astype(np.int64))]


def split_keys(shards: list[Shard], seed: int, shard_ids: list[int], val_fraction: float):
    """``{"train", "val", "test"}`` -> keys ``(N, 2)`` int64 (file position, instance index).

    ``test``: the shards' test maps. ``val``: ``round(val_fraction * n_train_maps)`` of each
    shard's train maps (at least one, and one left for training, when ``val_fraction > 0``),
    drawn with a generator seeded by ``(seed, shard id)``; ``train``: the other train maps.
    """
    if not 0.0 <= val_fraction < 1.0:
        raise ValueError(f"val_fraction must be in [0, 1), got {val_fraction}")
    out: dict[str, list[np.ndarray]] = {name: [] for name in SPLIT_NAMES}
    for pos, (shard, sid) in enumerate(zip(shards, shard_ids, strict=True)):
        train_maps = np.flatnonzero(shard.arrays["split"] == TRAIN)
        rng = np.random.default_rng(np.random.SeedSequence([seed, sid, 0x76616C]))
        n_val = int(round(val_fraction * len(train_maps)))
        if val_fraction > 0 and len(train_maps) > 1:
            n_val = min(max(n_val, 1), len(train_maps) - 1)  # at least one map in each
        val_maps = rng.choice(train_maps, n_val, replace=False)
        inst_map = shard.arrays["inst_map"]
        split_of = np.where(np.isin(inst_map, val_maps), 1, 0)  # 0 train, 1 val
        split_of[shard.arrays["split"][inst_map] != TRAIN] = 2  # test
        for k, name in enumerate(SPLIT_NAMES):
            idx = np.flatnonzero(split_of == k)
            out[name].append(np.stack([np.full(len(idx), pos), idx], axis=1))
    return {k: np.concatenate(v).astype(np.int64) for k, v in out.items()}


def evaluation_keys(shards: list[Shard], n: int | None) -> np.ndarray:
    """The evaluation instances: ``n`` evenly spaced keys ``(R, 2)`` int64 (file position,
    instance index) of the test split (the shards' test maps, in shard order)."""
    test = split_keys(shards, 0, list(range(len(shards))), 0.0)["test"]
    return evenly_spaced(test, n)
