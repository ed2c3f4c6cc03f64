"""The command line: map and heatmap formats (map images at any bit depth, transparency,
0/1 occupancy), named instances, references that follow the endpoints, exit codes (an
internal error is not a budget hit), one-line errors without tracebacks, the figure,
--version and ``python -m vnrrt``."""

import subprocess
import sys

import cv2
import numpy as np
import pytest
from omegaconf import OmegaConf

from vnrrt.cli.main import main
from vnrrt.config import CONF_DIR, section
from vnrrt.data.build import build_shard
from vnrrt.data.build_named import build_named_maps
from vnrrt.data.config import LabelsConfig
from vnrrt.maps.config import DataConfig
from vnrrt.planners import PlannerConfig


@pytest.fixture
def map_npy(tmp_path):
    g = np.zeros((80, 80), np.uint8)
    g[:, 38:42] = 1
    g[35:45, 38:42] = 0
    path = tmp_path / "map.npy"
    np.save(path, g)
    return path


@pytest.fixture(scope="module")
def named(tmp_path_factory):
    path = tmp_path_factory.mktemp("named") / "named_maps.npz"
    build_named_maps(path, 200, LabelsConfig())
    return path


def test_the_package_defaults_equal_conf_planner_default():
    """The CLI needs no conf/ at run time: its defaults are PlannerConfig's, kept equal."""
    conf = section({"planner": OmegaConf.load(CONF_DIR / "planner/default.yaml")}, "planner",
                   PlannerConfig)  # fmt: skip
    assert conf == PlannerConfig()


def test_plan_npy_optimal_writes_figure(map_npy, tmp_path, capsys):
    out = tmp_path / "plan.png"
    rc = main(["plan", "--map", str(map_npy), "--start", "8.5,8.5", "--goal", "72.5,8.5",
               "--stop", "optimal", "--set", "eta=8", "--out", str(out)])  # fmt: skip
    text = capsys.readouterr().out
    assert rc == 0 and "success=True" in text and "exact" in text
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
    data = DataConfig(size=64, n_obstacles=[2, 4], obstacle_size=[6.0, 12.0], bar_width=[2.0, 3.0],
                      n_starts=2, n_goals=2, min_start_goal_distance=10.0)  # fmt: skip
    shard = tmp_path / "shard_0.npz"
    build_shard(shard, 0, seed=1, maps_per_shard=1, data=data, labels=LabelsConfig(), workers=1)
    rc = main(["plan", "--map", str(shard), "--instance", "3", "--stop", "optimal"])
    assert rc == 0 and "cost/A*" in capsys.readouterr().out


def test_named_maps_by_name_and_a_moved_start_gets_its_own_reference(named, capsys):
    assert main(["plan", "--map", str(named), "--instance", "u_trap"]) == 0
    assert "success=True" in capsys.readouterr().out
    rc = main(["plan", "--map", str(named), "--instance", "2", "--start", "130.5,170.5",
               "--stop", "optimal", "--set", "max_seconds=20"])  # fmt: skip
    text = capsys.readouterr().out
    ratio = float(text.split("cost/A* ")[1].split()[0])
    assert rc == 0 and ratio <= 1.01  # not the stored instance's 344.99 px
    assert "ref=344.99" not in text


def test_start_equal_to_goal_is_a_zero_length_plan(map_npy, capsys):
    rc = main(["plan", "--map", str(map_npy), "--start", "8.5,8.5", "--goal", "8.5,8.5"])
    assert rc == 0 and "n/a" in capsys.readouterr().out


@pytest.mark.parametrize(
    ("extra", "message"),
    [
        (["--start", "39.5,8.5", "--goal", "72.5,8.5"], "obstacle"),
        (["--start", "8.5,8.5", "--goal", "72.5,8.5", "--planner", "vnrrt_star"], "--checkpoint"),
        (["--start", "8.5,8.5", "--goal", "72.5,8.5", "--set", "etta=3"], "unknown"),
        (["--goal", "72.5,8.5"], "--start"),
        (["--start", "8.5,8.5", "--goal", "72.5,8.5", "--set", "max_iterations=1e12"],
         "max_iterations"),
        (["--start", "8.5,8.5", "--goal", "72.5,8.5", "--planner", "m_vnrrt_star", "--tau",
          "1.5"], "--tau"),
        (["--start", "8.5,8.5", "--goal", "72.5,8.5", "--out", "{tmp}"], "directory"),
        (["--start", "8.5,8.5", "--goal", "72.5,8.5", "--config", "{tmp}/broken.yaml"],
         "not valid YAML"),
        (["--instance", "3"], "--instance"),
    ],
)  # fmt: skip
def test_bad_input_is_one_line_and_exit_code_2(map_npy, tmp_path, capsys, extra, message):
    (tmp_path / "broken.yaml").write_text("eta: [1, 2\n")
    args = [a.format(tmp=tmp_path) for a in extra]
    assert main(["plan", "--map", str(map_npy), *args]) == 2
    err = capsys.readouterr().err
    assert message in err and err.count("\n") == 1 and "Traceback" not in err


def test_an_all_black_png_is_a_grayscale_map_of_obstacles(tmp_path, capsys):
    """Rule: a PNG is a class map only when it holds a start (2) and a goal (3) pixel; an
    all-black image is a grayscale map whose dark pixels are obstacles, not a free map."""
    cv2.imwrite(str(tmp_path / "black.png"), np.zeros((40, 40), np.uint8))
    rc = main(["plan", "--map", str(tmp_path / "black.png"), "--start", "5.5,5.5",
               "--goal", "30.5,30.5"])  # fmt: skip
    assert rc == 2 and "obstacle" in capsys.readouterr().err


def test_a_huge_budget_allocates_as_it_goes(map_npy):
    """The tree grows with the work: a budget of 10^12 iterations is no 14 TiB allocation."""
    rc = main(["plan", "--map", str(map_npy), "--start", "8.5,8.5", "--goal", "72.5,8.5",
               "--stop", "optimal", "--set", "max_iterations=1000000000000"])  # fmt: skip
    assert rc == 0


def test_budget_hit_exit_code_1(map_npy):
    """(The paper's protocol: the default configuration answers this straight query at once.)"""
    args = ["--start", "8.5,8.5", "--goal", "72.5,8.5", "--set", "max_iterations=5",
            "--config", "default"]  # fmt: skip
    assert main(["plan", "--map", str(map_npy), *args]) == 1


def test_version_and_module_entry_point_with_plain_help():
    out = subprocess.run([sys.executable, "-m", "vnrrt", "--version"], capture_output=True,
                         text=True, check=True).stdout  # fmt: skip
    assert out.startswith("vnrrt 0.")
    help_text = subprocess.run([sys.executable, "-m", "vnrrt", "--help"], capture_output=True,
                               text=True, check=True).stdout  # fmt: skip
    assert "vnrrt plan" in help_text and "``" not in help_text and ":func:" not in help_text


def test_an_edited_shard_beside_its_manifest_is_refused(tmp_path, capsys):
    """A shard rebuilt (valid, but not the one the manifest records) is refused by the CLI
    and by the stage that reads shards for the evaluation, naming the shard."""
    from vnrrt.data.manifest import ShardError, build_manifest, verified_files
    from vnrrt.data.shards import shard_file

    shards = tmp_path / "shards"
    build_shard(shard_file(shards, 0), 0, 0, 2, DataConfig(), LabelsConfig(), workers=1)
    build_manifest(shards, [0], tmp_path / "manifest.json")
    assert main(["plan", "--map", str(shard_file(shards, 0)), "--instance", "0"]) == 0
    build_shard(shard_file(shards, 0), 0, 1, 2, DataConfig(), LabelsConfig(), workers=1)
    capsys.readouterr()
    assert main(["plan", "--map", str(shard_file(shards, 0)), "--instance", "0"]) == 2
    err = capsys.readouterr().err.strip()
    assert "shard_0.npz does not match its checksum" in err and "\n" not in err
    with pytest.raises(ShardError, match="does not match its checksum"):
        verified_files(shards, tmp_path / "manifest.json", [0])  # as run_instances calls it


def wall_png(path, bits: int, wall: float) -> None:
    """A 40x40 gray picture at ``bits`` bits: white floor, a full-height wall of gray level
    ``wall`` (in [0, 1]) in columns 18-21."""
    full = 2**bits - 1
    img = np.full((40, 40), full, np.uint8 if bits == 8 else np.uint16)
    img[:, 18:22] = round(wall * full)
    cv2.imwrite(str(path), img)


@pytest.mark.parametrize("bits", [8, 16])
def test_a_dark_gray_wall_is_an_obstacle_at_any_bit_depth(tmp_path, capsys, bits):
    """A 30% gray wall is dark in an 8-bit and in a 16-bit PNG alike (it used to be free in
    16 bits, where the threshold was the absolute value 128 of 65535)."""
    wall_png(tmp_path / "map.png", bits, 0.3)
    args = ["plan", "--map", str(tmp_path / "map.png"), "--goal", "35.5,20.5"]
    assert main([*args, "--start", "19.5,20.5"]) == 2  # on the wall
    assert "lies in an obstacle cell" in capsys.readouterr().err
    assert main([*args, "--start", "5.5,20.5"]) == 1  # walled off: the budget runs out
    assert "success=False" in capsys.readouterr().out


def test_a_transparent_background_and_a_0_1_occupancy_png_are_free_space(tmp_path, capsys):
    """Black ink on a transparent background (alpha 0) and a 0/1 occupancy image both plan
    around their one wall (both used to read as all obstacle)."""
    ink = np.zeros((40, 40, 4), np.uint8)
    ink[10:40, 18:22, 3] = 255  # an opaque black wall from the bottom, open at the top
    cv2.imwrite(str(tmp_path / "ink.png"), ink)
    occupancy = (ink[..., 3] > 0).astype(np.uint8)
    cv2.imwrite(str(tmp_path / "occ.png"), occupancy)
    for name in ("ink.png", "occ.png"):
        rc = main(["plan", "--map", str(tmp_path / name), "--start", "5.5,35.5",
                   "--goal", "35.5,35.5", "--stop", "optimal"])  # fmt: skip
        text = capsys.readouterr().out
        assert rc == 0 and "success=True" in text, (name, text)
        ratio = float(text.split("cost/A* ")[1].split()[0])
        assert 0.9 < ratio <= 1.01  # the A* reference goes over the wall's top too


def test_an_internal_error_exits_3_with_its_traceback_not_1(map_npy, capsys, monkeypatch):
    """1 means "stopped on a budget"; an unexpected exception is a bug: status 3, the
    traceback and one line saying so."""
    import vnrrt.planners

    def broken(*args, **kwargs):
        raise RuntimeError("boom")

    monkeypatch.setattr(vnrrt.planners, "plan", broken)
    assert main(["plan", "--map", str(map_npy), "--start", "8.5,8.5", "--goal", "72.5,8.5"]) == 3
    err = capsys.readouterr().err
    assert "Traceback" in err and err.strip().splitlines()[-1].startswith(
        "vnrrt plan: internal error (RuntimeError: boom)"
    )


def test_the_help_lists_every_exit_status():
    help_text = subprocess.run([sys.executable, "-m", "vnrrt", "--help"], capture_output=True,
                               text=True, check=True).stdout  # fmt: skip
    flat = " ".join(help_text.split())
    for status in ("0 success", "1 the planner stopped on a budget", "2 bad configuration",
                   "3 an internal error"):  # fmt: skip
        assert status in flat, status
