"""Training data over the shards, rendered on the fly (no dense images on disk).

Splits are by base map, so no map lends instances to two splits: the shards' test maps are the
``test`` split; of each shard's train maps a seeded ``val_fraction`` (by ``(seed, shard id)``)
form ``val``, the rest ``train``. Instances are keyed ``(shard position, instance index)`` in
shard order; ``*_instances`` limits keep evenly spaced keys (spread over many maps, no RNG).
The training loader shuffles each epoch with a generator seeded by ``(shuffle_seed, epoch)``
(:class:`EpochShuffle`, so resuming mid-run repeats no batch order); workers are seeded by
Lightning (``seed_everything(seed, workers=True)``) and the dataset itself draws no random
numbers, so an item depends only on its key.
"""

from __future__ import annotations

import logging
from pathlib import Path

import lightning as L
import numpy as np
import torch
from torch.utils.data import DataLoader, Dataset, Sampler

from vnrrt.data.manifest import verified_files
from vnrrt.data.reader import Shard
from vnrrt.data.splits import SPLIT_NAMES, evenly_spaced, split_keys
from vnrrt.data.targets import check_target, label_masks, target_mask
from vnrrt.maps.render import NORMALIZATIONS, class_map, colorize, to_input

log = logging.getLogger(__name__)


class InstanceDataset(Dataset):
    """Items of the instances ``keys`` ``(N, 2)`` int64 ``(file position, instance index)`` of
    shard ``files``. Each item is a dict (``S`` = map size):

    ``image`` (3, S, S) float32 network input; ``classes`` (S, S) uint8 pixel classes;
    ``target`` (S, S) uint8 training target; ``vertices``, ``path``, ``interior`` and
    ``endpoints`` (S, S) bool A* label cells (undilated, for the metrics:
    :func:`vnrrt.data.targets.label_masks`); ``key`` (2,) int64 (shard id, instance).
    """

    def __init__(self, files, shard_ids, keys, target="vertex", target_radius=0.0,
                 target_endpoints="both", marker_radius=2.0,
                 normalize="imagenet") -> None:  # fmt: skip
        check_target(target, target_radius, target_endpoints)
        if normalize not in NORMALIZATIONS:
            raise ValueError(f"normalize must be one of {NORMALIZATIONS}, got {normalize!r}")
        self.files, self.shard_ids = [Path(f) for f in files], list(shard_ids)
        self.keys = np.asarray(keys, np.int64).reshape(-1, 2)
        self.target, self.target_radius = target, target_radius
        self.target_endpoints = target_endpoints
        self.marker_radius, self.normalize = marker_radius, normalize
        self._shards: dict[int, Shard] = {}

    def __len__(self) -> int:
        return len(self.keys)

    def shard(self, pos: int) -> Shard:
        """The loaded shard at file position ``pos`` (loaded once per process)."""
        if pos not in self._shards:
            self._shards[pos] = Shard(self.files[pos])
        return self._shards[pos]

    def __getitem__(self, n: int) -> dict[str, torch.Tensor]:
        pos, i = (int(v) for v in self.keys[n])
        shard = self.shard(pos)
        inst = shard.instance(i)
        grid = shard.grid(inst["map_index"])
        path, vertices = shard.path(i), shard.vertices(i)
        classes = class_map(grid, inst["start"], inst["goal"], self.marker_radius)
        shape = grid.shape
        target = target_mask(
            path, vertices, shape, self.target, self.target_radius, self.target_endpoints
        )
        masks = {k: torch.from_numpy(v) for k, v in label_masks(path, vertices, shape).items()}
        return {
            "image": torch.from_numpy(to_input(colorize(classes), self.normalize)),
            "classes": torch.from_numpy(classes),
            "target": torch.from_numpy(target.astype(np.uint8)),
            **masks,
            "key": torch.tensor([self.shard_ids[pos], i], dtype=torch.int64),
        }


class EpochShuffle(Sampler[int]):
    """A permutation of ``range(n)`` per epoch from a generator seeded by ``(seed, epoch)``.

    An epoch's order does not depend on how training got there, so a run resumed from a
    checkpoint sees the same batches as an uninterrupted one. Lightning calls
    :meth:`set_epoch` at the start of every epoch (and wraps the sampler under DDP).
    """

    def __init__(self, n: int, seed: int = 0) -> None:
        self.n, self.seed, self.epoch = n, seed, 0

    def set_epoch(self, epoch: int) -> None:
        self.epoch = epoch

    def __iter__(self):
        state = np.random.SeedSequence([self.seed, self.epoch, 0x657063]).generate_state(1)
        gen = torch.Generator().manual_seed(int(state[0]))
        return iter(torch.randperm(self.n, generator=gen).tolist())

    def __len__(self) -> int:
        return self.n


class ShardDataModule(L.LightningDataModule):
    """Train/val/test loaders over verified shards (module doc: splits, limits, seeding).

    Args:
        shards_dir, manifest: where the shards and their manifest are (``paths`` config).
        shards: shard ids to use (``scale.shards``).
        target, target_radius, target_endpoints: training target (``vertex``/``path``), its
            dilation (px) and the path ends it keeps (:mod:`vnrrt.data.targets`).
        marker_radius, normalize: start/goal disk radius (px) and input normalisation
            (:mod:`vnrrt.maps.render`).
        val_fraction: share of each shard's train maps held out for validation.
        train_instances, val_instances, test_instances: evenly spaced subsets (None: all).
        batch_size: per process; num_workers: loader processes (0: in the main process).
        seed: split seed; shuffle_seed: shuffling seed (None: ``seed``), so that a training
            seed (``train.seed``) changes the batch order but not the validation maps.
    """

    def __init__(self, shards_dir: str, manifest: str, shards: list[int], target: str = "vertex",
                 target_radius: float = 0.0, target_endpoints: str = "both",
                 marker_radius: float = 2.0,
                 normalize: str = "imagenet", val_fraction: float = 0.1,
                 train_instances: int | None = None, val_instances: int | None = 256,
                 test_instances: int | None = 256, batch_size: int = 16, num_workers: int = 0,
                 pin_memory: bool = False, seed: int = 0,
                 shuffle_seed: int | None = None) -> None:  # fmt: skip
        super().__init__()
        check_target(target, target_radius, target_endpoints)
        if batch_size < 1 or num_workers < 0:
            raise ValueError(f"need batch_size >= 1, num_workers >= 0: {batch_size}, {num_workers}")
        self.shards_dir, self.manifest, self.shard_ids = shards_dir, manifest, list(shards)
        self.item_args = {"target": target, "target_radius": target_radius,
                          "target_endpoints": target_endpoints, "marker_radius": marker_radius,
                          "normalize": normalize}  # fmt: skip
        self.val_fraction, self.seed = val_fraction, seed
        self.shuffle_seed = seed if shuffle_seed is None else shuffle_seed
        self.limits = {"train": train_instances, "val": val_instances, "test": test_instances}
        self.batch_size, self.num_workers, self.pin_memory = batch_size, num_workers, pin_memory
        self.datasets: dict[str, InstanceDataset] = {}

    def setup(self, stage: str | None = None) -> None:
        """Verify the shards against the manifest and build the three split datasets."""
        if self.datasets:
            return
        files = verified_files(self.shards_dir, self.manifest, self.shard_ids)
        keys = split_keys([Shard(f) for f in files], self.seed, self.shard_ids, self.val_fraction)
        for name in SPLIT_NAMES:
            chosen = evenly_spaced(keys[name], self.limits[name])
            self.datasets[name] = InstanceDataset(files, self.shard_ids, chosen, **self.item_args)
        sizes = {k: len(v) for k, v in self.datasets.items()}
        log.info("instances per split (of %s): %s", self.shard_ids, sizes)

    def _loader(self, split: str, shuffle: bool = False) -> DataLoader:
        data = self.datasets[split]
        sampler = EpochShuffle(len(data), self.shuffle_seed) if shuffle else None
        return DataLoader(
            data, batch_size=self.batch_size, sampler=sampler, num_workers=self.num_workers,
            pin_memory=self.pin_memory, persistent_workers=self.num_workers > 0,
        )  # fmt: skip

    def train_dataloader(self) -> DataLoader:
        return self._loader("train", shuffle=True)

    def val_dataloader(self) -> DataLoader:
        return self._loader("val")

    def test_dataloader(self) -> DataLoader:
        return self._loader("test")
