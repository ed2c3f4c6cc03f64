"""`vnrrt plan`: map formats, exit codes, printed result and figure."""

import cv2
import numpy as np
import pytest

from vnrrt.cli import main
from vnrrt.data.config import LabelsConfig
from vnrrt.maps.config import DataConfig


@pytest.fixture
def map_npy(tmp_path):
    g = np.zeros((80, 80), np.uint8)
    g[:, 38:42] = 1
    g[35:45, 38:42] = 0
    path = tmp_path / "map.npy"
    np.save(path, g)
    return path


def test_plan_npy_optimal_writes_figure(map_npy, tmp_path, capsys):
    out = tmp_path / "plan.png"
    rc = main(["plan", "--map", str(map_npy), "--start", "8.5,8.5", "--goal", "72.5,8.5",
               "--stop", "optimal", "--set", "eta=8", "--out", str(out)])  # fmt: skip
    text = capsys.readouterr().out
    assert rc == 0 and "success=True" in text and "any-angle" in text
    assert out.stat().st_size > 5_000


def test_plan_class_png_with_heatmap(tmp_path, capsys):
    img = np.zeros((60, 60), np.uint8)
    img[10:50, 28:32] = 1
    img[5, 5], img[54, 55] = 2, 3  # start and goal pixels (cell centres are used)
    cv2.imwrite(str(tmp_path / "map.png"), img)
    np.save(tmp_path / "heat.npy", np.full((60, 60), 0.1))
    rc = main(["plan", "--map", str(tmp_path / "map.png"), "--planner", "m_vnrrt_star",
               "--heatmap", str(tmp_path / "heat.npy"), "--tau", "0.05"])  # fmt: skip
    assert rc == 0 and "m_vnrrt_star: success=True" in capsys.readouterr().out


def test_plan_shard_instance(tmp_path, capsys):
    from vnrrt.data.build import build_shard

    data = DataConfig(size=64, n_obstacles=[2, 4], obstacle_size=[6.0, 12.0], bar_width=[2.0, 3.0],
                      n_starts=2, n_goals=2, min_start_goal_distance=10.0)  # fmt: skip
    shard = tmp_path / "shard_0.npz"
    build_shard(shard, 0, seed=1, maps_per_shard=1, data=data, labels=LabelsConfig(), workers=1)
    rc = main(["plan", "--map", str(shard), "--instance", "3", "--stop", "optimal"])
    assert rc == 0 and "cost/A*" in capsys.readouterr().out


@pytest.mark.parametrize(
    ("extra", "message"),
    [
        (["--start", "39.5,8.5", "--goal", "72.5,8.5"], "obstacle"),
        (["--start", "8.5,8.5", "--goal", "72.5,8.5", "--planner", "vnrrt_star"], "heatmap"),
        (["--start", "8.5,8.5", "--goal", "72.5,8.5", "--set", "etta=3"], "unknown"),
        (["--goal", "72.5,8.5"], "--start"),
    ],
)
def test_bad_input_exit_code_2(map_npy, capsys, extra, message):
    assert main(["plan", "--map", str(map_npy), *extra]) == 2
    assert message in capsys.readouterr().err


def test_budget_hit_exit_code_1(map_npy):
    args = ["--start", "8.5,8.5", "--goal", "72.5,8.5", "--set", "max_iterations=5"]
    assert main(["plan", "--map", str(map_npy), *args]) == 1
