"""Shards: contents against independent checks, determinism, split, bad files, manifest."""

import json
import zipfile

import numpy as np
import pytest

from tests.search.test_astar import assert_valid_path
from vnrrt.data.build import build_shard, split_of_maps
from vnrrt.data.build_named import build_named_maps
from vnrrt.data.config import LabelsConfig
from vnrrt.data.manifest import build_manifest, verify_manifest
from vnrrt.data.reader import Shard
from vnrrt.data.shards import FIELDS, ShardError, read_arrays, shard_file, write_shard
from vnrrt.maps.config import DataConfig
from vnrrt.search import astar, path_length, path_vertices

MAPS = 3


@pytest.fixture(scope="module")
def shard_dir(tmp_path_factory):
    out = tmp_path_factory.mktemp("shards")
    for sid in (0, 1):
        build_shard(shard_file(out, sid), sid, 0, MAPS, DataConfig(), LabelsConfig(), workers=1)
    return out


def test_instances_are_optimal_valid_paths_with_paper_vertices(shard_dir):
    shard = Shard(shard_file(shard_dir, 0))
    assert shard.n_maps == MAPS and shard.n_instances == MAPS * 144
    for i in range(shard.n_instances):
        inst, path = shard.instance(i), shard.path(i)
        grid = shard.grid(inst["map_index"])
        assert_valid_path(grid, path, inst["start"], inst["goal"])
        assert path_length(path) == pytest.approx(inst["length"], abs=1e-9)
        assert np.array_equal(shard.vertices(i), path_vertices(path))
    for i in range(0, shard.n_instances, 37):  # independent optimum on a sample
        inst = shard.instance(i)
        _, ref = astar(shard.grid(inst["map_index"]), inst["start"], inst["goal"])
        assert inst["length"] == pytest.approx(ref, abs=1e-9)


def test_every_start_goal_pair_appears_once_per_map(shard_dir):
    shard = Shard(shard_file(shard_dir, 1))
    a = shard.arrays
    for m in range(shard.n_maps):
        sel = a["inst_map"] == m
        pairs = {(tuple(s), tuple(g)) for s, g in zip(a["inst_start"][sel], a["inst_goal"][sel])}
        expected = {(tuple(s), tuple(g)) for s in a["starts"][m] for g in a["goals"][m]}
        assert pairs == expected and sel.sum() == 144


def test_masks_match_paths(shard_dir):
    shard = Shard(shard_file(shard_dir, 0))
    pm, vm = shard.path_mask(5), shard.vertex_mask(5)
    assert pm.sum() == len({tuple(c) for c in shard.path(5)})
    assert vm.sum() == len(shard.vertices(5)) and np.all(pm[vm])


def test_shard_bytes_are_deterministic_and_worker_independent(shard_dir, tmp_path):
    again = tmp_path / "again.npz"
    build_shard(again, 1, 0, MAPS, DataConfig(), LabelsConfig(), workers=2)
    assert again.read_bytes() == shard_file(shard_dir, 1).read_bytes()
    other = tmp_path / "other_seed.npz"
    build_shard(other, 1, 1, MAPS, DataConfig(), LabelsConfig(), workers=1)
    assert other.read_bytes() != again.read_bytes()


def test_split_is_by_map_70_30_and_disjoint(shard_dir):
    split = split_of_maps(0, 5, 100, 0.7)
    assert split.sum() == 30
    ids = {0: set(), 1: set()}
    for sid in (0, 1):
        a = Shard(shard_file(shard_dir, sid)).arrays
        for mid, s in zip(a["map_ids"], a["split"]):
            ids[int(s)].add(int(mid))
    assert not ids[0] & ids[1] and len(ids[0] | ids[1]) == 2 * MAPS
    shard = Shard(shard_file(shard_dir, 0))
    train, test = shard.instances("train"), shard.instances("test")
    maps_of = shard.arrays["inst_map"]
    assert not set(maps_of[train]) & set(maps_of[test])
    assert len(train) + len(test) == shard.n_instances


def test_named_maps_shard(tmp_path):
    out = tmp_path / "named.npz"
    build_named_maps(out, 200, LabelsConfig())
    shard = Shard(out)
    assert shard.n_instances == 5 and shard.meta["names"][2] == "narrow_passage"
    assert np.all(shard.arrays["split"] == 1)


def _corrupt(path, tmp_path, **changes):
    arrays = read_arrays(path)
    arrays.update(changes)
    out = tmp_path / "bad.npz"
    with zipfile.ZipFile(out, "w") as zf:
        for k, v in arrays.items():
            if v is not None:
                with zf.open(f"{k}.npy", "w") as f:
                    np.lib.format.write_array(f, np.asarray(v))
    return out


def test_bad_shards_give_clear_errors(shard_dir, tmp_path):
    good = shard_file(shard_dir, 0)
    with pytest.raises(ShardError, match="does not exist"):
        Shard(tmp_path / "missing.npz")
    junk = tmp_path / "junk.npz"
    junk.write_bytes(b"not a zip at all")
    with pytest.raises(ShardError, match="corrupt"):
        Shard(junk)
    with pytest.raises(ShardError, match="format version 99"):
        Shard(_corrupt(good, tmp_path, format_version=np.array(99)))
    with pytest.raises(ShardError, match="lacks fields \\['inst_length'\\]"):
        Shard(_corrupt(good, tmp_path, inst_length=None))
    with pytest.raises(ShardError, match="'inst_goal' has shape"):
        Shard(_corrupt(good, tmp_path, inst_goal=np.zeros((3, 2), np.uint16)))
    offs = read_arrays(good)["path_offsets"].copy()
    offs[-1] += 1
    with pytest.raises(ShardError, match="path_offsets"):
        Shard(_corrupt(good, tmp_path, path_offsets=offs))
    with pytest.raises(ShardError, match="lacks fields"):
        write_shard(tmp_path / "x.npz", {k: np.zeros(1) for k in list(FIELDS)[:3]})
    assert not list(tmp_path.glob("*.tmp-*")), "a failed write left a temp file"


def test_manifest_counts_checksums_and_tamper_detection(shard_dir, tmp_path):
    manifest = shard_dir / "manifest.json"
    summary = build_manifest(shard_dir, [0, 1], manifest)
    assert summary["instances"] == 2 * MAPS * 144 and summary["maps"] == 2 * MAPS
    assert summary["train_instances"] + summary["test_instances"] == summary["instances"]
    assert summary["bytes_per_instance"] < 700
    assert [p.name for p in verify_manifest(manifest)] == ["shard_0.npz", "shard_1.npz"]
    doc = json.loads(manifest.read_text())
    doc["shards"][1]["sha256"] = "0" * 64
    bad = shard_dir / "bad_manifest.json"
    bad.write_text(json.dumps(doc))
    with pytest.raises(ShardError, match="shard_1.npz does not match its checksum"):
        verify_manifest(bad)


def test_an_interrupted_write_leaves_neither_file_nor_temp(tmp_path):
    from vnrrt.infra.io import atomic_write_bytes

    target = tmp_path / "out.bin"

    def dies(f):
        f.write(b"half")
        raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        atomic_write_bytes(target, dies)
    assert list(tmp_path.iterdir()) == []
