"""Shard jobs as Hydra multiruns (vnrrt.pipeline.multirun) through the joblib launcher and through
submitit on a real one-node SLURM cluster: the shard files are byte for byte those of stage
``shard@<id>``, and ``dvc commit`` makes ``dvc repro`` skip them."""

import os
import subprocess
import sys
from pathlib import Path

import pytest

from tests.conftest import copy_pipeline
from vnrrt.config import compose, section
from vnrrt.data.build import build_shard
from vnrrt.data.config import LabelsConfig, ScaleConfig
from vnrrt.data.shards import shard_file
from vnrrt.maps.config import DataConfig

SMOKE = ["scale=smoke"]
SHARDS = (0, 1)
SWEEP = "multirun/test"  # Hydra's sweep dir, relative to the scratch copy


def run(cmd: list[str], cwd: Path, env: dict, timeout: float = 300) -> str:
    """Run ``cmd`` in ``cwd``; fail the test with its output unless it exits 0."""
    proc = subprocess.run(cmd, cwd=cwd, env=env, capture_output=True, text=True, timeout=timeout)
    assert proc.returncode == 0, f"{' '.join(cmd)} failed:\n{proc.stdout}\n{proc.stderr}"
    return proc.stdout + proc.stderr


@pytest.fixture(scope="module")
def expected(tmp_path_factory) -> dict[int, bytes]:
    """Smoke shards built by ``build_shard`` directly, with the arguments stage shard@<id>
    passes (tests/pipeline/test_pipeline.py checks the stage against the same call)."""
    cfg = compose(SMOKE)
    out = tmp_path_factory.mktemp("direct")
    data, labels = section(cfg, "data", DataConfig), section(cfg, "labels", LabelsConfig)
    maps = section(cfg, "scale", ScaleConfig).maps_per_shard
    for s in SHARDS:
        build_shard(shard_file(out, s), s, int(cfg.seed), maps, data, labels, workers=1)
    return {s: shard_file(out, s).read_bytes() for s in SHARDS}


@pytest.fixture
def scratch(tmp_path, repo) -> tuple[Path, dict]:
    """A scratch copy of the pipeline with a DVC repo (no git) and smoke ``params.yaml``,
    and the environment to run commands in it."""
    copy_pipeline(repo, tmp_path)
    bin_dir = Path(sys.executable).parent
    env = dict(
        os.environ,
        PATH=f"{bin_dir}{os.pathsep}{os.environ['PATH']}",
        VNRRT_CONF_DIR=str(tmp_path / "conf"),
        DVC_NO_ANALYTICS="1",
    )
    run(["dvc", "init", "--no-scm", "-q"], tmp_path, env)
    run(
        [sys.executable, "-m", "vnrrt.pipeline.params", *SMOKE, "--out", "params.yaml"],
        tmp_path,
        env,
    )
    return tmp_path, env


def multirun(work: Path, env: dict, *overrides: str) -> str:
    """``python -m vnrrt.pipeline.multirun -m`` over the smoke shards, one core per job."""
    ids = ",".join(map(str, SHARDS))
    cmd = [
        sys.executable,
        "-m",
        "vnrrt.pipeline.multirun",
        "-m",
        "+stage=shard",
        f"+part={ids}",
        *SMOKE,
    ]
    return run([*cmd, "workers=1", f"hydra.sweep.dir={SWEEP}", *overrides], work, env)


def assert_same_shards(work: Path, expected: dict[int, bytes]) -> None:
    for s, data in expected.items():
        assert shard_file(work / "data/smoke/shards", s).read_bytes() == data, f"shard {s}"


@pytest.mark.slow
def test_joblib_multirun_writes_the_stage_shards_and_dvc_commit_makes_them_current(
    scratch, expected
):
    work, env = scratch
    multirun(work, env, "hydra/launcher=local")
    assert_same_shards(work, expected)
    assert len(list((work / SWEEP).glob("*/.hydra/config.yaml"))) == len(SHARDS)

    run(["dvc", "repro", "validate"], work, env)  # the check every stage depends on
    run(["dvc", "commit", "-f", "shard"], work, env)
    assert "up to date" in run(["dvc", "status", "shard"], work, env)
    out = run(["dvc", "repro", "manifest"], work, env)  # the data stages and their consumer
    for s in SHARDS:
        assert f"Stage 'shard@{s}' didn't change" in out
    assert "Running stage 'manifest'" in out
    assert_same_shards(work, expected)


def test_submitit_slurm_multirun_writes_the_stage_shards(scratch, expected, slurm):
    work, env = scratch
    env["SLURM_CONF"] = slurm
    launcher = ["hydra/launcher=slurm", "hydra.launcher.cpus_per_task=1"]
    multirun(work, env, *launcher, "hydra.launcher.mem_gb=1", "hydra.launcher.timeout_min=5")
    assert_same_shards(work, expected)
    logs = sorted((work / SWEEP / ".submitit").glob("*_*/*_log.out"))  # <job>_<task>/
    assert len(logs) == len(SHARDS), "each shard ran as a task of one SLURM array job"
