"""Mutation check of the A* tests (slow): each deliberate bug below, applied to a copy of the
package, must make ``tests/search/test_astar.py`` fail. A test suite that stays green on a
wrong A* would let a longer-than-optimal reference into every "optimal" stop rule."""

import os
import shutil
import subprocess
import sys

import pytest

ASTAR = "src/vnrrt/search/astar.py"
MUTATIONS = {
    "overestimating heuristic": (
        "return max(ax, ay) + (math.sqrt(2.0) - 1.0) * min(ax, ay)",
        "return max(ax, ay) + min(ax, ay)",
    ),
    "diagonal costs 1": ("_COST = MOVE_COSTS.copy()", "_COST = np.ones(8)"),
    "corner cutting": (
        "if m >= 4 and (grid[y, nx] or grid[ny, x]):",
        "if m >= 4 and False:",
    ),
    "improvements refused": ("if ng < g[n] - 1e-12:", "if ng < g[n] - 1.0:"),
}


@pytest.mark.slow
@pytest.mark.parametrize("name", sorted(MUTATIONS))
def test_each_mutation_of_astar_is_caught(name, repo, tmp_path):
    old, new = MUTATIONS[name]
    copy = tmp_path / "repo"
    shutil.copytree(repo / "src", copy / "src", ignore=shutil.ignore_patterns("__pycache__"))
    shutil.copytree(repo / "tests", copy / "tests", ignore=shutil.ignore_patterns("__pycache__"))
    shutil.copy(repo / "pyproject.toml", copy / "pyproject.toml")
    source = (copy / ASTAR).read_text()
    assert old in source, f"mutation {name!r} no longer applies: update it"
    (copy / ASTAR).write_text(source.replace(old, new))
    env = dict(os.environ, PYTHONPATH=str(copy / "src"), NUMBA_CACHE_DIR=str(tmp_path / "nb"),
               CI="1")  # fmt: skip
    proc = subprocess.run([sys.executable, "-m", "pytest", "-q", "-x", "-p", "no:cacheprovider",
                           "tests/search/test_astar.py"], cwd=copy, env=env,
                          capture_output=True, text=True, timeout=900)  # fmt: skip
    assert proc.returncode != 0, f"mutation {name!r} survived:\n{proc.stdout[-2000:]}"
