"""vnrrt works outside the repository: a wheel installed into a fresh virtual environment
imports from there and answers its command line from another folder (no conf/, no source
tree); the slow test also plans on a PNG map there (the installed package compiles its numba
kernels afresh, ~45 s: its cache is keyed by the source files' paths)."""

import shutil
import site
import subprocess
import sys
import venv
from pathlib import Path

import cv2
import numpy as np
import pytest


@pytest.fixture(scope="module")
def installed(repo, tmp_path_factory) -> tuple[Path, str, Path]:
    """``(python, purelib, folder)``: the wheel of the repository installed into a fresh
    virtual environment, and an empty folder outside the repository."""
    tmp_path = tmp_path_factory.mktemp("wheel")
    source = tmp_path / "source"  # a copy: setuptools leaves build/ in the tree it builds
    shutil.copytree(repo / "src", source / "src", ignore=shutil.ignore_patterns("__pycache__"))
    for name in ("pyproject.toml", "README.md", "LICENSE"):
        shutil.copy(repo / name, source / name)
    subprocess.run([sys.executable, "-m", "pip", "wheel", "--no-deps", "--no-build-isolation",
                    "-q", "-w", str(tmp_path / "dist"), str(source)], check=True,
                   capture_output=True)  # fmt: skip
    wheel = next((tmp_path / "dist").glob("vnrrt-*.whl"))
    env_dir = tmp_path / "env"
    venv.create(env_dir, with_pip=False)
    py = env_dir / "bin" / "python"
    code = "import sysconfig; print(sysconfig.get_paths()['purelib'])"
    purelib = subprocess.run([py, "-c", code], capture_output=True, text=True, check=True)
    purelib = purelib.stdout.strip()
    # the dependencies from this environment (a path line: its .pth files, among them the
    # editable install of the repository, are not run), vnrrt itself from the wheel
    deps = [p for p in site.getsitepackages() if Path(p).is_dir()]
    Path(purelib, "deps.pth").write_text("\n".join(deps) + "\n")
    subprocess.run([sys.executable, "-m", "pip", "install", "--no-deps", "-q", "--target",
                    purelib, str(wheel)], check=True, capture_output=True)  # fmt: skip
    work = tmp_path / "elsewhere"
    work.mkdir()
    return py, purelib, work


def test_the_wheel_installs_and_answers_outside_the_repository(installed, repo):
    py, purelib, work = installed
    code = "import vnrrt, vnrrt.planners, vnrrt.cli.main; print(vnrrt.__file__)"
    where = subprocess.run([py, "-c", code], cwd=work, capture_output=True, text=True,
                           check=True).stdout  # fmt: skip
    assert str(repo) not in where and purelib in where
    assert Path(purelib, "vnrrt", "py.typed").is_file()
    out = subprocess.run([py, "-m", "vnrrt", "--version"], cwd=work, capture_output=True,
                         text=True, check=True).stdout  # fmt: skip
    assert out.strip() == f"vnrrt {__import__('vnrrt').__version__}"
    out = subprocess.run([py, "-m", "vnrrt", "plan", "--help"], cwd=work, capture_output=True,
                         text=True, check=True).stdout  # fmt: skip
    assert "--map" in out and "--stop" in out
    # the library's defaults and the composition read the conf/ packaged in the wheel
    code = ("import vnrrt.config as c, vnrrt.maps.config as m, vnrrt.planners as p; "
            "m.DataConfig(); c.compose([]); print(c.CONF_DIR, p.FASTEST.informed)")  # fmt: skip
    out = subprocess.run([py, "-c", code], cwd=work, capture_output=True, text=True,
                         check=True).stdout  # fmt: skip
    assert out.startswith(purelib) and out.strip().endswith("True")


@pytest.mark.slow
def test_the_wheel_plans_outside_the_repository(installed):
    py, _, work = installed
    img = np.full((60, 60), 255, np.uint8)
    img[10:50, 28:32] = 0  # a dark wall
    cv2.imwrite(str(work / "map.png"), img)
    out = subprocess.run([py, "-m", "vnrrt", "plan", "--map", "map.png", "--start", "5.5,30.5",
                          "--goal", "55.5,30.5", "--stop", "optimal", "--out", "plan.png"],
                         cwd=work, capture_output=True, text=True)  # fmt: skip
    assert out.returncode == 0, out.stdout + out.stderr
    assert "success=True" in out.stdout and (work / "plan.png").stat().st_size > 3000
