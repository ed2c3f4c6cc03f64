"""Networks on maps of any size and shape: the heatmap of a map padded to the encoder's
stride (``pad=True``) equals the heatmap of the same content padded by hand to a size the
stride divides, cropped (no shift); padding is a no-op where the stride divides the map;
``vnrrt predict`` reads MovingAI ``.map`` files. A small random-weight VertexNet in a
checkpoint written as vnrrt.train writes them (no training needed: the checks are about
geometry, not about what the network learned)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import torch

from tests.conftest import REPO
from vnrrt.cli.main import main
from vnrrt.maps.movingai import read_map
from vnrrt.model.checkpoint import NETWORK_CLASS, seal
from vnrrt.model.record import RECORD_KEY
from vnrrt.model.vertexnet import VertexNet
from vnrrt.predict.api import heatmap, load_model, stride

NET = {"_target_": NETWORK_CLASS, "encoder": "resnet18", "out_channels": 2, "in_channels": 3,
       "decoder_width": 0.25, "encoder_width": 0.25}  # fmt: skip


@pytest.fixture(scope="module")
def ckpt(tmp_path_factory) -> Path:
    torch.manual_seed(0)
    kwargs = {k: v for k, v in NET.items() if k != "_target_"}
    net = VertexNet(**kwargs, weights=None, freeze_encoder=False).eval()
    record = {"network": "vertexnet", "net": NET,
              "target": {"kind": "vertex", "endpoints": "both", "radius": 1.0},
              "render": {"marker_radius": 2.0, "normalize": "imagenet"}}  # fmt: skip
    state = {f"net.{k}": v for k, v in net.state_dict().items()}
    path = tmp_path_factory.mktemp("net") / "vertexnet.ckpt"
    torch.save(seal({"state_dict": state, RECORD_KEY: record}), path)
    return path


def _by_hand(grid: np.ndarray, k: int) -> np.ndarray:
    h, w = grid.shape
    return np.pad(grid, ((0, -h % k), (0, -w % k)), constant_values=1)


@pytest.mark.parametrize(("h", "w"), [(194, 193), (37, 70), (64, 96), (200, 200)])
def test_a_padded_heatmap_is_the_divisible_maps_heatmap_cropped(ckpt, h, w):
    rng = np.random.default_rng(h * w)
    grid = (rng.random((h, w)) < 0.2).astype(np.uint8)
    start, goal = (1, 2), (w - 3, h - 2)
    grid[2, 1] = grid[h - 2, w - 3] = 0
    k = stride(load_model(ckpt).net)
    assert k == 32
    padded = heatmap(ckpt, grid, start, goal, pad=True)
    assert padded.shape == (h, w)
    whole = heatmap(ckpt, _by_hand(grid, k), start, goal)
    assert whole.shape[0] % k == 0 and whole.shape[1] % k == 0
    assert np.array_equal(padded, whole[:h, :w])
    if h % k == 0 and w % k == 0:
        assert np.array_equal(padded, heatmap(ckpt, grid, start, goal))
    else:  # unpadded: the network's own resizing at odd sizes gives another heatmap
        plain = heatmap(ckpt, grid, start, goal)
        assert plain.shape == (h, w) and not np.array_equal(plain, padded)


def test_a_shifted_map_gives_a_shifted_heatmap_at_the_stride(ckpt):
    """Content moved by one stride (32 px) right and down moves the heatmap with it: the
    heatmaps agree at that shift far better than at any shift one pixel off it."""
    rng = np.random.default_rng(3)
    grid = (rng.random((70, 90)) < 0.15).astype(np.uint8)
    grid[10, 10] = grid[60, 80] = 0
    moved = np.ones((102, 122), np.uint8)
    moved[32:, 32:] = grid
    a = heatmap(ckpt, grid, (10, 10), (80, 60), pad=True)
    b = heatmap(ckpt, moved, (42, 42), (112, 92), pad=True)
    inner = (slice(24, 46), slice(24, 66))  # away from the borders, whose reach differs

    def gap(dy: int, dx: int) -> float:  # a against b moved back by 32 px + (dx, dy)
        back = b[32 + dy : 32 + dy + 70, 32 + dx : 32 + dx + 90]
        return float(np.abs(a[inner] - back[inner]).max())

    off_by_one = min(gap(dy, dx) for dy in (-1, 0, 1) for dx in (-1, 0, 1) if dy or dx)
    assert gap(0, 0) < 0.2 * off_by_one


def test_predict_reads_a_movingai_map(ckpt, tmp_path, capsys):
    path = REPO / "data" / "movingai" / "lak304d.map"
    out = tmp_path / "heat.npy"
    args = ["predict", "--checkpoint", str(ckpt), "--map", str(path), "--start", "10.5,115.5",
            "--goal", "116.5,182.5", "--out", str(out)]  # fmt: skip
    assert main([*args, "--pad"]) == 0
    heat = np.load(out)
    assert heat.shape == read_map(path).shape == (194, 193)
    assert np.array_equal(heat, heatmap(ckpt, read_map(path), (10, 115), (116, 182), pad=True))
    assert "heatmap 193x194" in capsys.readouterr().out


def test_a_scen_batch_plans_with_a_checkpoints_heatmaps(ckpt, capsys):
    mai = REPO / "data" / "movingai"
    base = ["plan", "--map", str(mai / "lak304d.map"), "--scen", str(mai / "lak304d.map.scen"),
            "--longest", "2", "--checkpoint", str(ckpt), "--pad"]  # fmt: skip
    assert main([*base, "--planner", "vnrrt_star"]) == 0
    out = capsys.readouterr().out
    assert "solved 2 of 2 planned" in out and "planner vnrrt_star" in out
    assert main([*base, "--planner", "nrrt_star"]) == 2  # a vertex network: not NRRT*'s target
    assert "predicts vertex heatmaps, not the path heatmaps" in capsys.readouterr().err


def test_plan_on_a_map_file_with_a_padded_networks_heatmap(ckpt, tmp_path, capsys):
    args = ["plan", "--map", str(REPO / "data" / "movingai" / "lak304d.map"), "--start",
            "10.5,115.5", "--goal", "116.5,182.5", "--planner", "vnrrt_star", "--checkpoint",
            str(ckpt), "--pad", "--out", str(tmp_path / "plan.png")]  # fmt: skip
    assert main(args) == 0
    out = capsys.readouterr().out
    assert "vnrrt_star: success=True" in out and (tmp_path / "plan.png").is_file()
