"""The predict stage: float16 heatmaps of the evaluation instances, equal to the network's
output on the rendered instance, with their metrics and the Fig. 3 figure."""

import json
from pathlib import Path

import numpy as np
import pytest
import torch

from tests.train_helpers import small_cfg
from vnrrt.data.datamodule import evaluation_keys
from vnrrt.data.heatmaps import HeatmapError, read_heatmaps
from vnrrt.data.reader import Shard
from vnrrt.maps.render import render_instance
from vnrrt.model.checkpoint import load_network
from vnrrt.pipeline import run_predict


@pytest.fixture(scope="module")
def predicted(small_data, trained):
    cfg = small_cfg(small_data, trained, "predict.test_instances=6")
    return cfg, run_predict(cfg)


def test_heatmap_files_hold_the_named_maps_and_the_evaluation_instances(predicted, small_data):
    cfg, results = predicted
    shards = [Shard(small_data / "shards" / f"shard_{s}.npz") for s in cfg.scale.shards]
    keys = evaluation_keys(shards, 6)
    for name, target in (("vertexnet", "vertex"), ("nrrtnet", "path")):
        h = read_heatmaps(f"{cfg.paths.heatmaps}/{name}.npz")
        assert h["named"].shape == (5, 64, 64) and h["named"].dtype == np.float16
        assert h["test"].shape == (6, 64, 64) and h["test"].dtype == np.float16
        assert h["test"].min() >= 0.0 and h["test"].max() <= 1.0
        np.testing.assert_array_equal(h["test_keys"][:, 1], keys[:, 1])
        np.testing.assert_array_equal(
            h["test_keys"][:, 0], np.asarray(cfg.scale.shards)[keys[:, 0]]
        )
        assert h["meta"]["network"] == name and h["meta"]["target"]["kind"] == target
        assert results[name]["test_instances"] == 6 and results[name]["ms_per_map"] > 0
    saved = json.loads(Path(f"{cfg.paths.metrics}/predict.json").read_text())
    assert set(saved) == {"vertexnet", "nrrtnet"}
    assert "test/mass_near_vertex_uniform" in saved["vertexnet"]
    assert Path(f"{cfg.paths.figures}/heatmaps.png").read_bytes()[:4] == b"\x89PNG"


def test_a_heatmap_is_the_network_output_on_the_rendered_instance(predicted, small_data):
    cfg, _ = predicted
    h = read_heatmaps(f"{cfg.paths.heatmaps}/vertexnet.npz")
    net, record = load_network(f"{cfg.paths.models}/vertexnet.ckpt")
    shard_id, i = h["test_keys"][3]
    shard = Shard(small_data / "shards" / f"shard_{shard_id}.npz")
    inst = shard.instance(i)
    image = render_instance(shard.grid(inst["map_index"]), inst["start"], inst["goal"],
                            **record["render"])  # fmt: skip
    with torch.no_grad():
        want = net(torch.from_numpy(image)[None]).softmax(1)[0, 1].numpy()
    np.testing.assert_allclose(h["test"][3].astype(np.float32), want, atol=1e-3)


def test_missing_heatmaps_are_named(tmp_path):
    with pytest.raises(HeatmapError, match="nothing.npz does not exist"):
        read_heatmaps(tmp_path / "nothing.npz")
