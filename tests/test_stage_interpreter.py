"""A stage run by a ``python`` that lacks vnrrt (``.venv/bin/dvc exp run`` without the venv
activated) says so in one line: it runs again with the repository's ``.venv/bin/python``
where there is one, else ends with status 2 naming what to do (stages/_interpreter.py)."""

import os
import subprocess
import sys
from pathlib import Path

import pytest

from tests.conftest import copy_pipeline
from vnrrt.config import compose, dump

BASE = Path(sys.base_prefix) / "bin" / "python3"  # the interpreter this venv was made from


@pytest.fixture(scope="module")
def work(repo, tmp_path_factory):
    dest = copy_pipeline(repo, tmp_path_factory.mktemp("stages"))
    (dest / "params.yaml").write_text(dump(compose([])))
    return dest


def _bare(work, *args):
    if sys.prefix == sys.base_prefix or not BASE.is_file():
        pytest.skip("the tests do not run in a virtual environment")
    probe = subprocess.run([BASE, "-c", "import vnrrt"], capture_output=True)
    if probe.returncode == 0:
        pytest.skip(f"{BASE} can import vnrrt itself")
    env = {k: v for k, v in os.environ.items() if k not in ("VIRTUAL_ENV", "PYTHONPATH")}
    return subprocess.run([BASE, *args], cwd=work, capture_output=True, text=True, env=env,
                          timeout=300)  # fmt: skip


def test_without_a_venv_the_stage_says_what_to_do_in_one_line(work):
    assert not (work / ".venv").exists()
    out = _bare(work, "stages/validate.py")
    assert out.returncode == 2, out.stderr
    assert out.stderr.count("\n") == 1 and "Traceback" not in out.stderr, out.stderr
    assert out.stderr.startswith("stage validate: error: ") and "cannot import vnrrt" in out.stderr
    assert "source .venv/bin/activate" in out.stderr and "make repro" in out.stderr


def test_with_the_repository_venv_the_stage_runs_with_it(work):
    (work / ".venv").symlink_to(Path(sys.prefix), target_is_directory=True)
    try:
        out = _bare(work, "stages/validate.py")
    finally:
        (work / ".venv").unlink()
    assert out.returncode == 0, out.stderr
    first = out.stderr.splitlines()[0]
    assert first.startswith("stage validate: ") and "running with" in first, out.stderr
    assert str(work / ".venv" / "bin" / "python") in first
