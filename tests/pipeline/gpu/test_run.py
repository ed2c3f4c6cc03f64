"""The GPU run of issue 27 (``scripts/gpu/paper_network.sh``, :mod:`vnrrt.pipeline.gpu`) end to
end on the CPU with a tiny budget and tiny sizes, under an import blocker for what the GPU machine
lacks; the returned files read back through the pipeline's reader; the reader's checks."""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import torch

from tests.train_helpers import SMALL
from vnrrt.data.heatmaps import read_heatmaps, write_heatmaps
from vnrrt.data.returned import NETWORKS, Instances, ReturnedError, check_limits, read_returned
from vnrrt.data.shards import shard_file
from vnrrt.evaluation.instances import build_instances
from vnrrt.infra.io import sha256
from vnrrt.pipeline.gpu.bundle import make_bundle
from vnrrt.pipeline.gpu.predict import metric_settings
from vnrrt.predict.batch import heatmap_metrics

BLOCKED = ("hydra", "omegaconf", "mlflow", "dvc")  # not installed on the GPU machine
BLOCKER = f"""import importlib.abc, sys
class _Block(importlib.abc.MetaPathFinder):
    def find_spec(self, name, path, target=None):
        if name.split(".")[0] in {BLOCKED!r}:
            raise ModuleNotFoundError(f"No module named {{name!r}} (blocked)", name=name)
sys.meta_path.insert(0, _Block())
"""
RANDOM = 4  # random instances in the instances file, beside the five named maps
ARGS = ["--device", "cpu", "--budget", "12", "--min-batch", "2", "--max-batch", "4",
        "--max-shards", "2"]  # fmt: skip


@pytest.fixture(scope="module")
def bundle(small_data, tmp_path_factory) -> Path:
    """The 64x64 smoke data's instances file and a bundle of the tiny network (bf16)."""
    root = tmp_path_factory.mktemp("gpu")
    files = [shard_file(small_data / "shards", s) for s in (0, 1)]
    build_instances(root / "instances.npz", small_data / "named_maps.npz", files, [0, 1],
                    RANDOM, workers=1)  # fmt: skip
    make_bundle(root / "instances.npz", root / "bundle", [*SMALL, "trainer.precision=bf16-mixed"])
    return root


@pytest.fixture(scope="module")
def blocked_env(tmp_path_factory, repo) -> dict:
    """The environment of a Python that cannot import :data:`BLOCKED` (a sitecustomize)
    and imports vnrrt from this repository; one torch thread (on a shared machine, more
    threads than free cores made the run 4x slower)."""
    folder = tmp_path_factory.mktemp("blocker")
    (folder / "sitecustomize.py").write_text(BLOCKER)
    path = os.pathsep.join([str(folder), str(repo / "src")])
    return {**os.environ, "PYTHONPATH": path, "PYTHON": sys.executable, "OMP_NUM_THREADS": "1"}


@pytest.fixture(scope="module")
def returned(bundle, blocked_env, repo) -> Path:
    """The script's output folder after one run on the CPU (work files in ``../work``)."""
    out, work = bundle / "out", bundle / "work"
    cmd = ["bash", str(repo / "scripts/gpu/paper_network.sh"), *ARGS, "--bundle",
           str(bundle / "bundle"), "--out", str(out), "--work", str(work)]  # fmt: skip
    proc = subprocess.run(cmd, env=blocked_env, capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stdout[-3000:] + proc.stderr[-3000:]
    return out


def test_the_script_runs_without_what_the_gpu_machine_lacks(returned, blocked_env):
    # the run above succeeded under the blocker; the blocker does block, vnrrt's imports too
    for module in ("omegaconf", "vnrrt.pipeline.training"):
        proc = subprocess.run([sys.executable, "-c", f"import {module}"], env=blocked_env,
                              capture_output=True, text=True)  # fmt: skip
        assert proc.returncode != 0 and "(blocked)" in proc.stderr, module


def test_the_returned_files_fit_the_limits_and_read_back(returned, bundle):
    files = check_limits(returned)
    assert set(files) == {"heatmaps/part_0.npz", "metrics.json", "curves.csv", "run.log"}
    instances = Instances(bundle / "instances.npz")
    got = read_returned(returned, instances)
    assert np.array_equal(got["keys"], instances.keys) and len(instances) == 5 + RANDOM
    for heat in got["maps"].values():
        assert heat.shape == (len(instances), 64, 64) and heat.dtype == np.float16
    assert set(got["metrics"]["networks"]) == set(NETWORKS)
    assert got["meta"][0]["budget_s"] == 12 and got["meta"][0]["machine"]["device"] == "cpu"


def test_the_heatmaps_are_the_trained_checkpoints_predictions(returned, bundle):
    from vnrrt.model.checkpoint import load_network
    from vnrrt.predict.api import Model, heatmap

    instances = Instances(bundle / "instances.npz")
    got = read_returned(returned, instances)
    for name, trained in NETWORKS.items():
        ckpt = bundle / "work" / f"{trained}.ckpt"
        assert sha256(ckpt) == got["meta"][0]["networks"][name]["checkpoint_sha256"]
        model = Model(*load_network(ckpt, trained))
        for i in (0, len(instances) - 1):  # a named map and a random instance
            inst = instances[i]
            ref = heatmap(model, inst.grid, inst.start_cell, inst.goal_cell)
            np.testing.assert_allclose(got["maps"][name][i], ref, atol=2e-3)


def test_the_metrics_are_those_of_the_returned_heatmaps(returned, bundle):
    instances = Instances(bundle / "instances.npz")
    config = json.loads((bundle / "bundle" / "run_config.json").read_text())
    got = read_returned(returned, instances)
    rows = np.flatnonzero(np.array(instances.kinds) == "random")
    for name in NETWORKS:
        ref = heatmap_metrics(got["maps"][name][rows], instances, rows, metric_settings(config))
        recorded = got["metrics"]["networks"][name]["heldout"]
        assert recorded["test_instances"] == RANDOM
        for key, value in ref.items():
            assert recorded[f"test/{key}"] == pytest.approx(value, abs=1e-6), key


def test_the_run_records_its_training_and_data(returned):
    doc = json.loads((returned / "metrics.json").read_text())
    probe = doc["probe"]
    sizes = [r["batch"] for r in probe["sizes"]]  # until the probe share is spent
    assert sizes in ([2], [2, 4]) and probe["batch"] == sizes[-1]
    assert doc["data"]["heldout"] == {"regenerated": RANDOM, "differ": 0}
    curves = (returned / "curves.csv").read_text().splitlines()
    for name in NETWORKS:
        train = doc["networks"][name]["train"]
        assert train["train_images"] == train["steps"] * probe["batch"] > 0
        assert train["steps"] <= train["planned_steps"]
        losses = [line for line in curves if line.startswith(f"{name},")]
        assert losses, f"no curve rows of {name}"


def _copy(returned: Path, tmp_path: Path) -> Path:
    out = tmp_path / "out"
    shutil.copytree(returned, out)
    return out


def _rewrite(out: Path, change) -> None:
    """Rewrite part 0 with ``change(keys, maps, meta)`` applied."""
    part = out / "heatmaps" / "part_0.npz"
    got = read_heatmaps(part)
    keys, maps, meta = change(got["keys"].copy(), dict(got["maps"]), got["meta"])
    write_heatmaps(part, keys, maps, **meta)


def _reversed(keys, maps, meta):
    return keys[::-1], {n: m[::-1] for n, m in maps.items()}, meta


def _over_one(keys, maps, meta):
    maps["paper_nrrtnet"] = maps["paper_nrrtnet"].copy()
    maps["paper_nrrtnet"][0, 0, 0] = 1.5
    return keys, maps, meta


def _no_images(keys, maps, meta):
    del meta["networks"]["paper_vertexnet"]["images_seen"]
    return keys, maps, meta


def _one_network(keys, maps, meta):
    del maps["paper_nrrtnet"]
    return keys, maps, meta


@pytest.mark.parametrize(
    ("change", "message"),
    [
        (_reversed, "not the keys of"),
        (_over_one, "not finite in \\[0, 1\\]"),
        (_no_images, "paper_vertexnet lacks \\['images_seen'\\]"),
        (_one_network, "networks \\['paper_vertexnet'\\], expected"),
    ],
)
def test_the_reader_names_what_is_wrong_in_a_heatmap_file(returned, bundle, tmp_path, change,
                                                          message):  # fmt: skip
    out = _copy(returned, tmp_path)
    _rewrite(out, change)
    with pytest.raises(ReturnedError, match=message):
        read_returned(out, bundle / "instances.npz")


def test_the_reader_refuses_float32_heatmaps(returned, bundle, tmp_path):
    out = _copy(returned, tmp_path)
    part = out / "heatmaps" / "part_0.npz"
    with np.load(part) as npz:
        arrays = {k: npz[k] for k in npz.files}
    arrays["net_paper_vertexnet"] = arrays["net_paper_vertexnet"].astype(np.float32)
    np.savez_compressed(part, **arrays)
    with pytest.raises(ReturnedError, match="paper_vertexnet is float32"):
        read_returned(out, bundle / "instances.npz")


@pytest.mark.parametrize(
    ("extra", "size", "message"),
    [
        (["a.txt", "b.txt", "c.txt", "d.txt", "e.txt"], 1, "at most 8 files"),
        (["big.bin"], (16 << 20) + 1, "big.bin' has 16777217 bytes"),
        (["a b.txt"], 1, "a name the machine drops"),
        (["a/b/c/deep.txt"], 1, "too deep"),
    ],
)
def test_the_reader_checks_the_machines_return_limits(returned, bundle, tmp_path, extra, size,
                                                      message):  # fmt: skip
    out = _copy(returned, tmp_path)
    for name in extra:
        (out / name).parent.mkdir(parents=True, exist_ok=True)
        (out / name).write_bytes(b"x" * size)
    with pytest.raises(ReturnedError, match=message):
        read_returned(out, bundle / "instances.npz")


def test_a_returned_folder_needs_its_metrics(returned, bundle, tmp_path):
    out = _copy(returned, tmp_path)
    (out / "metrics.json").unlink()
    with pytest.raises(ReturnedError, match="metrics.json is missing"):
        read_returned(out, bundle / "instances.npz")
    assert read_returned(out / "heatmaps", bundle / "instances.npz")["metrics"] is None


def test_the_reader_refuses_heatmaps_of_another_instances_file(returned, bundle, tmp_path):
    with np.load(bundle / "instances.npz") as npz:
        arrays = {k: npz[k] for k in npz.files}
    arrays["exact_length"] = arrays["exact_length"] + 1.0  # same keys, other content
    np.savez_compressed(tmp_path / "instances.npz", **arrays)
    with pytest.raises(ReturnedError, match="predicted another instances file"):
        read_returned(returned, tmp_path / "instances.npz")


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--device", "tpu"], "--device must be one of"),
        (["--budget", "0"], "--budget must be positive"),
        (["--max-batch", "1"], "--min-batch <= --max-batch"),
        (["--train-share", "0.5"], "shares must be positive"),
    ],
)
def test_bad_arguments_are_one_line_errors(bundle, tmp_path, capsys, args, message):
    from vnrrt.pipeline.gpu.run import main

    base = ["--device", "cpu", "--budget", "10", "--bundle", str(bundle / "bundle"),
            "--out", str(tmp_path / "out")]  # fmt: skip
    assert main([*base, *args]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and message in err
    assert not (tmp_path / "out").exists()


def test_a_missing_bundle_is_named(tmp_path, capsys):
    from vnrrt.pipeline.gpu.run import main

    assert main(["--device", "cpu", "--budget", "10", "--bundle", str(tmp_path),
                 "--out", str(tmp_path / "out")]) == 2  # fmt: skip
    assert f"bundle {tmp_path} has no run_config.json" in capsys.readouterr().err


def test_instances_beyond_the_return_limits_fail_before_any_work():
    from vnrrt.data.returned import heatmap_parts

    assert heatmap_parts(205, 200, 2) == 3  # the CPU scale's instances: 31 MiB in 3 parts
    with pytest.raises(ReturnedError, match="use an instances file with fewer instances"):
        heatmap_parts(1000, 200, 2)


def test_an_evaluation_instance_on_a_training_map_is_refused(small_data, bundle):
    from vnrrt.data.reader import TRAIN, Shard
    from vnrrt.pipeline.gpu.data import check_heldout

    files = [shard_file(small_data / "shards", s) for s in (0, 1)]
    instances = Instances(bundle / "instances.npz")
    assert check_heldout(instances, files) == {"regenerated": RANDOM, "differ": 0}
    shard = Shard(files[0])
    j = int(np.flatnonzero(shard.arrays["split"] == TRAIN)[0])
    leaked = type("Leaked", (), {"arrays": {k: v.copy() for k, v in instances.arrays.items()}})
    leaked.arrays["cluster"][-1] = shard.arrays["map_ids"][j]
    leaked.arrays["grids"][-1] = shard.arrays["maps"][j]
    with pytest.raises(ValueError, match="a training map here"):
        check_heldout(leaked, files)


def test_config_nodes_are_built_without_hydra():
    from vnrrt.pipeline.gpu.plan import build

    opt = build({"_target_": "torch.optim.AdamW", "_partial_": True, "lr": 0.1})
    assert opt.func is torch.optim.AdamW and opt.keywords == {"lr": 0.1}
    assert build({"_target_": "vnrrt.model.FocalLoss", "gamma": 1.0}).gamma == 1.0
    with pytest.raises(ValueError, match="'torch.optim.Nope' is not importable"):
        build({"_target_": "torch.optim.Nope"})


def test_compiling_pays_only_when_its_time_comes_back_and_the_loader_keeps_up():
    from vnrrt.pipeline.gpu.probe import compile_pays

    # 1.5x faster steps after 30 s of compiling: (T - 30) * 150 > T * 100 iff T > 90 s
    assert not compile_pays(100.0, 150.0, 30.0, loader=1e4, workers=4, seconds=80.0)
    assert compile_pays(100.0, 150.0, 30.0, loader=1e4, workers=4, seconds=100.0)
    # a loader at 100 images/s caps both: compiling never pays
    assert not compile_pays(100.0, 150.0, 30.0, loader=100.0, workers=4, seconds=1e4)


def test_planned_steps_end_on_a_validation():
    from vnrrt.pipeline.gpu.train import STEP_SLACK, planned_steps

    for rate, seconds, batch in ((100.0, 10.0, 8), (3000.0, 90.0, 512), (1.0, 1.0, 4)):
        steps, interval = planned_steps(rate, seconds, batch)
        assert steps % interval == 0 and steps >= 1
        assert steps <= max(1, STEP_SLACK * rate * seconds / batch)
