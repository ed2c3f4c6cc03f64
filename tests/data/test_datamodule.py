"""The data module: disjoint splits by map, determinism, items equal to the shard's labels,
seeded loaders, and shards verified against the manifest."""

import shutil

import numpy as np
import pytest
import torch
from hydra.utils import instantiate

from tests.train_helpers import small_cfg
from vnrrt.data.datamodule import EpochShuffle, ShardDataModule
from vnrrt.data.reader import Shard
from vnrrt.data.shards import ShardError
from vnrrt.data.splits import evaluation_keys, evenly_spaced
from vnrrt.maps.render import class_map


def make_dm(data, tmp_path, **kwargs) -> ShardDataModule:
    cfg = small_cfg(data, tmp_path)
    args = {"val_instances": None, "test_instances": None, **kwargs}
    dm = instantiate(cfg.train.datamodule, **args)
    dm.setup("fit")
    return dm


def map_ids(dm: ShardDataModule, split: str) -> set[tuple[int, int]]:
    ds = dm.datasets[split]
    return {(int(p), int(ds.shard(p).arrays["inst_map"][i])) for p, i in ds.keys}


def test_splits_are_disjoint_by_map_and_cover_every_instance(small_data, tmp_path):
    dm = make_dm(small_data, tmp_path)
    maps = {s: map_ids(dm, s) for s in ("train", "val", "test")}
    assert all(maps.values())
    assert not (maps["train"] & maps["val"] or maps["train"] & maps["test"]
                or maps["val"] & maps["test"])  # fmt: skip
    n = sum(len(dm.datasets[s]) for s in maps)
    shards = [Shard(f) for f in dm.datasets["train"].files]
    assert n == sum(s.n_instances for s in shards)
    test = dm.datasets["test"].keys
    for pos, shard in enumerate(shards):  # test = the shards' own test split
        np.testing.assert_array_equal(test[test[:, 0] == pos, 1], shard.instances("test"))


def test_splits_and_order_are_deterministic(small_data, tmp_path):
    a, b = make_dm(small_data, tmp_path), make_dm(small_data, tmp_path)
    c = make_dm(small_data, tmp_path, seed=5)
    for split in ("train", "val", "test"):
        np.testing.assert_array_equal(a.datasets[split].keys, b.datasets[split].keys)
    assert map_ids(a, "val") != map_ids(c, "val")
    first = [next(iter(dm.train_dataloader()))["key"] for dm in (a, b, c)]
    assert torch.equal(first[0], first[1]) and not torch.equal(first[0], first[2])


def test_each_epoch_has_its_own_seeded_order():
    sampler = EpochShuffle(50, seed=3)
    epoch0 = list(sampler)
    assert sorted(epoch0) == list(range(50)) and list(sampler) == epoch0
    sampler.set_epoch(1)
    epoch1 = list(sampler)
    assert epoch1 != epoch0
    fresh = EpochShuffle(50, seed=3)
    fresh.set_epoch(1)  # as when resuming at epoch 1
    assert list(fresh) == epoch1


def test_worker_processes_give_the_same_batches(small_data, tmp_path):
    single = make_dm(small_data, tmp_path, batch_size=3)
    workers = make_dm(small_data, tmp_path, batch_size=3, num_workers=2)
    for x, y in zip(list(single.val_dataloader()), list(workers.val_dataloader())):
        assert torch.equal(x["key"], y["key"]) and torch.equal(x["image"], y["image"])


@pytest.mark.parametrize(("target", "radius"), [("vertex", 0.0), ("path", 0.0), ("vertex", 1.0)])
def test_items_match_the_shard_labels(small_data, tmp_path, target, radius):
    dm = make_dm(small_data, tmp_path, target=target, target_radius=radius, marker_radius=1.0)
    ds = dm.datasets["train"]
    item = ds[5]
    pos, i = ds.keys[5]
    shard = ds.shard(pos)
    inst = shard.instance(i)
    s = shard.size
    assert item["image"].shape == (3, s, s) and item["image"].dtype == torch.float32
    assert item["key"].tolist() == [dm.shard_ids[pos], i]
    np.testing.assert_array_equal(item["vertices"], shard.vertex_mask(i))
    np.testing.assert_array_equal(item["path"], shard.path_mask(i))
    want = class_map(shard.grid(inst["map_index"]), inst["start"], inst["goal"], 1.0)
    np.testing.assert_array_equal(item["classes"], want)
    exact = shard.vertex_mask(i) if target == "vertex" else shard.path_mask(i)
    got = item["target"].numpy().astype(bool)
    assert got[exact].all() and (got.sum() > exact.sum()) == (radius > 0)


def test_limits_keep_evenly_spaced_instances(small_data, tmp_path):
    dm = make_dm(small_data, tmp_path, val_instances=5, test_instances=7)
    assert len(dm.datasets["val"]) == 5 and len(dm.datasets["test"]) == 7
    keys = np.arange(20).reshape(10, 2)
    np.testing.assert_array_equal(evenly_spaced(keys, 3), keys[[0, 4, 9]])
    assert evenly_spaced(keys, None) is keys
    shards = [Shard(f) for f in dm.datasets["test"].files]
    np.testing.assert_array_equal(evaluation_keys(shards, 7), dm.datasets["test"].keys)


def test_shards_are_verified_against_the_manifest(small_data, tmp_path):
    data = tmp_path / "data"
    shutil.copytree(small_data, data)
    with pytest.raises(ShardError, match="not listed in manifest"):
        make_dm(data, tmp_path, shards=[0, 1, 7])
    victim = data / "shards" / "shard_1.npz"
    victim.write_bytes(victim.read_bytes()[:-10] + b"0123456789")
    with pytest.raises(ShardError, match="shard_1.npz does not match its checksum"):
        make_dm(data, tmp_path)
