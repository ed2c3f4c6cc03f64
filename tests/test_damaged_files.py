"""One error contract for every file vnrrt reads: a damaged file of each kind (a flipped
byte, a truncation, a file of another format) is exit 2 with one line on stderr naming the
file, never exit 3 ("this is a bug") and never a traceback. Each file is read through its
real reader and the exit status of every vnrrt command (:func:`vnrrt.cli.stage.run_reporting`);
maps, shards and heatmaps through ``vnrrt plan``."""

import functools
import gzip
import io
import shutil
import zlib

import cv2
import numpy as np
import pytest
import torch

from tests.conftest import REPO
from vnrrt.cli.main import main
from vnrrt.cli.stage import run_reporting
from vnrrt.config import load_params, stage_params
from vnrrt.data.build import build_shard
from vnrrt.data.config import LabelsConfig
from vnrrt.data.heatmaps import read_heatmaps, write_heatmaps
from vnrrt.data.instances import Instances
from vnrrt.data.manifest import build_manifest, verify_manifest
from vnrrt.data.shards import shard_file
from vnrrt.evaluation.table import read_table, write_table
from vnrrt.maps.config import DataConfig
from vnrrt.model.checkpoint import read_checkpoint
from vnrrt.studies.paper_tables import load_paper_tables
from vnrrt.tracking.store import check_store

DAMAGES = ("flipped", "truncated", "foreign")


def damage(path, how: str, foreign, at: float = 0.5):
    """Damage ``path`` in place: flip every bit of the byte at ``at`` of its length, cut it
    to a third, or replace it by the bytes of ``foreign`` (a file of another format)."""
    raw = path.read_bytes()
    if how == "flipped":
        b = bytearray(raw)
        b[int(len(raw) * at)] ^= 0xFF
        path.write_bytes(bytes(b))
    elif how == "truncated":
        path.write_bytes(raw[: len(raw) // 3])
    else:
        path.write_bytes(foreign.read_bytes())
    return path


def assert_contract(capsys, read, path):
    """``read()`` run as a command: exit 2, one line on stderr naming ``path``."""
    assert run_reporting("test", read) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "Traceback" not in err and "bug" not in err, err
    assert str(path) in err, err


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    """A good file of each kind, built by the project's own writers."""
    d = tmp_path_factory.mktemp("good")
    build_shard(shard_file(d / "shards", 0), 0, 0, 1, DataConfig(), LabelsConfig(), workers=1)
    build_manifest(d / "shards", [0], d / "manifest.json")
    grid = np.zeros((64, 64), np.uint8)
    grid[20:40, 30] = 1
    np.save(d / "map.npy", grid)
    cv2.imwrite(str(d / "map.png"), (1 - grid) * 255)
    heat = np.random.default_rng(0).random((2, 64, 64)).astype(np.float32)
    write_heatmaps(d / "heat.npz", np.array([[0, 0], [0, 1]]), {"vertexnet": heat})
    meta = np.array('{"map_size": 64}')
    np.savez_compressed(d / "instances.npz", format_version=np.array(1), meta=meta,
                        keys=np.zeros((3, 2), np.int64), payload=np.arange(50_000))  # fmt: skip
    torch.save({"state_dict": {"w": torch.arange(50_000.0)}}, d / "net.ckpt")
    shutil.copy(REPO / "params.yaml", d / "params.yaml")
    shutil.copy(REPO / "data/paper/tables.yaml", d / "tables.yaml")
    shutil.copy(REPO / "dvc.yaml", d / "dvc.yaml")
    table = read_table(REPO / "reports/cpu/results/trials.csv.gz").iloc[:300]
    write_table(table, d / "trials.csv")
    with open(d / "trials.csv", "rb") as f, gzip.open(d / "trials.csv.gz", "wb") as g:
        shutil.copyfileobj(f, g)
    return d


@pytest.fixture
def copy(files, tmp_path):
    def make(name):
        dst = tmp_path / name
        dst.parent.mkdir(parents=True, exist_ok=True)
        shutil.copy(files / name, dst)
        return dst

    return make


def test_the_good_files_are_read(files):
    assert main(["plan", "--map", str(files / "map.npy"), "--start", "5.5,5.5",
                 "--goal", "50.5,50.5"]) == 0  # fmt: skip
    assert main(["plan", "--map", str(files / "map.png"), "--start", "5.5,5.5",
                 "--goal", "50.5,50.5"]) == 0  # fmt: skip
    assert len(read_heatmaps(files / "heat.npz")["keys"]) == 2
    assert len(Instances(files / "instances.npz")) == 3
    assert len(verify_manifest(files / "manifest.json")) == 1
    assert load_params(files / "params.yaml").seed == 0
    assert len(read_table(files / "trials.csv.gz")) == 300
    load_paper_tables(files / "tables.yaml")
    stage_params("evaluate", files / "dvc.yaml")


def _plan(*args):
    return lambda: main(["plan", *args, "--start", "5.5,5.5", "--goal", "50.5,50.5"])


@pytest.mark.parametrize("how", DAMAGES)
def test_maps_given_to_vnrrt_plan(files, copy, capsys, how):
    for name in ("map.npy", "map.png"):
        path = damage(copy(name), how, files / "params.yaml", at=0.02 if how == "flipped" else 0.5)
        assert main(["plan", "--map", str(path), "--start", "5.5,5.5", "--goal", "50.5,50.5"]) == 2
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and str(path) in err and "allow_pickle" not in err, err


def _inflate_breaking_flip(path) -> None:
    """Flip, in place, the first byte from the middle of ``path`` (an .npz) on whose flip
    inflating a member fails (``zlib.error``, not only its CRC check): the issue's case."""
    raw = path.read_bytes()
    for pos in range(len(raw) // 2, len(raw)):
        b = bytearray(raw)
        b[pos] ^= 0xFF
        try:
            with np.load(io.BytesIO(bytes(b)), allow_pickle=False) as npz:
                [npz[k] for k in npz.files]
        except zlib.error:
            path.write_bytes(bytes(b))
            return
        except Exception:
            continue
    raise AssertionError(f"no flip of {path} breaks inflation")


@pytest.mark.parametrize("how", [*DAMAGES, "inflate"])
def test_shards_given_to_vnrrt_plan(files, copy, capsys, how):
    path = copy("shards/shard_0.npz")
    if how == "inflate":
        _inflate_breaking_flip(path)
    else:
        damage(path, how, files / "map.png")
    assert main(["plan", "--map", str(path), "--instance", "0"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and str(path) in err and "zlib" not in err.split(":")[0], err


@pytest.mark.parametrize("how", DAMAGES)
def test_heatmaps_given_to_vnrrt_plan(files, copy, capsys, how):
    path = damage(copy("heat.npz"), how, files / "map.npy")
    args = ["plan", "--map", str(files / "map.npy"), "--heatmap", str(path), "--row", "0",
            "--network", "vertexnet", "--planner", "nrrt_star", "--start", "5.5,5.5",
            "--goal", "50.5,50.5"]  # fmt: skip
    assert main(args) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and str(path) in err, err


READERS = {  # file -> (reader, a file of another format)
    "instances.npz": (Instances, "map.npy"),
    "net.ckpt": (read_checkpoint, "heat.npz"),
    "params.yaml": (load_params, "map.png"),
    "tables.yaml": (load_paper_tables, "net.ckpt"),
    "dvc.yaml": (functools.partial(stage_params, "evaluate"), "map.png"),
    "trials.csv.gz": (read_table, "heat.npz"),
    "manifest.json": (verify_manifest, "map.png"),
}


@pytest.mark.parametrize("how", DAMAGES)
@pytest.mark.parametrize("name", list(READERS))
def test_every_other_kind_of_file(files, copy, capsys, name, how):
    reader, foreign = READERS[name]
    # text: an ASCII byte near the start, flipped to a byte that is not UTF-8
    at = 0.01 if name.endswith((".yaml", ".json")) else 0.5
    path = damage(copy(name), how, files / foreign, at)
    assert_contract(capsys, lambda: reader(path) and 0, path)


@pytest.mark.parametrize("how", DAMAGES)
def test_tracking_stores(files, copy, capsys, tmp_path, how):
    import sqlite3

    db = tmp_path / "mlflow.db"
    with sqlite3.connect(db) as con:
        con.execute("CREATE TABLE runs (id INTEGER PRIMARY KEY, name TEXT)")
        con.executemany("INSERT INTO runs (name) VALUES (?)", [("x" * 200,)] * 2000)
    con.close()
    damage(db, how, files / "params.yaml", at=4096 / db.stat().st_size)
    check_store.cache_clear()
    assert_contract(capsys, lambda: check_store(f"sqlite:///{db}") or 0, db)
