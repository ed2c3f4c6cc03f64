"""Shared test fixtures: hypothesis profile, small random grids, repository paths."""

from __future__ import annotations

import os
import shutil
import subprocess
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, settings

REPO = Path(__file__).resolve().parents[1]

settings.register_profile(
    "default", deadline=None, max_examples=60, suppress_health_check=[HealthCheck.too_slow]
)
settings.register_profile("ci", parent=settings.get_profile("default"), derandomize=True)
settings.load_profile("ci" if os.environ.get("CI") else "default")


@pytest.fixture(scope="session")
def repo() -> Path:
    return REPO


def random_grid(seed: int, h: int = 24, w: int = 24, density: float = 0.3) -> np.ndarray:
    """A small random occupancy grid (uint8, 1 = obstacle) for property tests."""
    rng = np.random.default_rng(seed)
    return (rng.random((h, w)) < density).astype(np.uint8)


@pytest.fixture(scope="session")
def small_data(tmp_path_factory) -> Path:
    """Smoke-scale shards, manifest and named maps on 64x64 maps (training tests)."""
    from tests.train_helpers import SMALL, build_data

    return build_data(tmp_path_factory.mktemp("small_data"), SMALL)


@pytest.fixture(scope="session")
def smoke_data(tmp_path_factory) -> Path:
    """The real smoke-scale data (200x200 maps) in a tmp dir."""
    from tests.train_helpers import build_data

    return build_data(tmp_path_factory.mktemp("smoke_data"), ["scale=smoke"])


@pytest.fixture(scope="session")
def trained(small_data, tmp_path_factory) -> Path:
    """Outputs (``models/vertexnet.ckpt``, ``models/nrrtnet.ckpt``, metrics) of two training
    steps of each network on the 64x64 smoke data."""
    from tests.train_helpers import QUICK, small_cfg
    from vnrrt.pipeline.training import run_train as train

    out = tmp_path_factory.mktemp("trained")
    cfg = small_cfg(small_data, out, *QUICK)
    for name in ("vertexnet", "nrrtnet"):
        train(cfg, name)
    return out


PIPELINE_FILES = ["dvc.yaml", "conf", "stages", "src", ".dvcignore", "data/paper", "data/movingai",
                  "reports/gpu"]  # fmt: skip
DVC_FILES = [".dvc/config", ".dvc/plots/series.json"]  # copied after `dvc init`


def copy_pipeline(repo: Path, dest: Path) -> Path:
    """Copy what `dvc repro` needs (pipeline, config, code, the paper's tables) into ``dest``
    for tests that run DVC in a scratch repository; returns ``dest``. numba's on-disk caches
    (``__pycache__/*.nbi``, ``*.nbc``) travel with the code, modification times kept, so the
    copy's stages load the compiled kernels instead of compiling them again (no ``.pyc``)."""
    for name in PIPELINE_FILES:
        src, dst = repo / name, dest / name
        dst.parent.mkdir(parents=True, exist_ok=True)
        if src.is_dir():
            shutil.copytree(src, dst, ignore=shutil.ignore_patterns("*.pyc"))
        else:
            shutil.copy(src, dst)
    return dest


def copy_dvc_files(repo: Path, dest: Path) -> None:
    """After ``dvc init`` in ``dest``: the project's DVC config and plot template."""
    for name in DVC_FILES:
        (dest / name).parent.mkdir(parents=True, exist_ok=True)
        shutil.copy(repo / name, dest / name)


@pytest.fixture(scope="session")
def slurm(tmp_path_factory, repo) -> Iterator[str]:
    """A one-node SLURM cluster on localhost (scripts/slurm/start.sh) for the test session;
    yields its ``SLURM_CONF`` and stops every daemon afterwards."""
    if not (shutil.which("slurmctld") and shutil.which("slurmd") and shutil.which("munged")):
        pytest.skip("slurmctld/slurmd/munged not installed (run .ci/slurm-setup)")
    if os.geteuid() != 0:
        pytest.skip("a local slurmd must run as root")
    state = tmp_path_factory.mktemp("slurm")
    start, stop = repo / "scripts/slurm/start.sh", repo / "scripts/slurm/stop.sh"
    try:
        proc = subprocess.run([start, state], capture_output=True, text=True, timeout=120)
        assert proc.returncode == 0, f"cluster did not start:\n{proc.stdout}\n{proc.stderr}"
        yield str(state / "slurm.conf")
    finally:
        subprocess.run([stop, state], capture_output=True, timeout=120, check=False)
