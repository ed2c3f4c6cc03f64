"""The predict stages: float16 heatmaps of the evaluation instances in parts, equal to the
network's output on the rendered instance, the named maps, the metrics and Fig. 3."""

import copy
import json
from pathlib import Path

import numpy as np
import pytest
import torch

from tests.train_helpers import small_cfg
from vnrrt.config import ConfigError
from vnrrt.data.datamodule import evaluation_keys
from vnrrt.data.heatmaps import HeatmapError, part_file, read_heatmaps, read_parts
from vnrrt.data.reader import Shard
from vnrrt.maps.render import render_instance
from vnrrt.model.checkpoint import load_network
from vnrrt.pipeline import run_predict_named, run_predict_part
from vnrrt.predict import heatmap_metrics

N_TEST = 7  # not a multiple of the number of parts


@pytest.fixture(scope="module")
def predicted(small_data, trained):
    cfg = small_cfg(
        small_data, trained, f"predict.test_instances={N_TEST}", "predict.parts=[0,1,2]"
    )
    parts = [run_predict_part(cfg, k) for k in (0, 1, 2)]
    return cfg, parts, run_predict_named(cfg)


def test_parts_hold_the_evaluation_instances_in_order(predicted, small_data):
    cfg, parts, _ = predicted
    shards = [Shard(small_data / "shards" / f"shard_{s}.npz") for s in cfg.scale.shards]
    keys = evaluation_keys(shards, N_TEST)
    sizes = [len(read_heatmaps(part_file(cfg.paths.heatmaps, k))["keys"]) for k in range(3)]
    assert sizes == [2, 2, 3] and [p["vertexnet"]["instances"] for p in parts] == sizes
    h = read_parts(cfg.paths.heatmaps, [0, 1, 2])
    np.testing.assert_array_equal(h["keys"][:, 1], keys[:, 1])
    np.testing.assert_array_equal(h["keys"][:, 0], np.asarray(cfg.scale.shards)[keys[:, 0]])
    for name, target in (("vertexnet", "vertex"), ("nrrtnet", "path")):
        test = h["maps"][name]
        assert test.shape == (N_TEST, 64, 64) and test.dtype == np.float16
        assert test.min() >= 0.0 and test.max() <= 1.0
        assert all(m["networks"][name]["target"]["kind"] == target for m in h["meta"])


def test_named_heatmaps_metrics_and_figure(predicted):
    cfg, _, results = predicted
    named = read_heatmaps(cfg.paths.named_heatmaps)
    np.testing.assert_array_equal(named["keys"], np.stack([[-1] * 5, range(5)], axis=1))
    for name in ("vertexnet", "nrrtnet"):
        assert named["maps"][name].shape == (5, 64, 64)
        assert results[name]["test_instances"] == N_TEST and results[name]["ms_per_map"] > 0
    saved = json.loads(Path(f"{cfg.paths.metrics}/predict.json").read_text())
    assert set(saved) == {"vertexnet", "nrrtnet"}
    assert "test/mass_near_vertex_uniform" in saved["vertexnet"]
    assert Path(f"{cfg.paths.figures}/heatmaps.png").read_bytes()[:4] == b"\x89PNG"


def test_test_metrics_do_not_depend_on_the_split(predicted, small_data, trained):
    """The merged metrics equal those of the same heatmaps predicted as one part."""
    cfg, _, results = predicted
    one = small_cfg(small_data, trained / "one", f"predict.test_instances={N_TEST}",
                    "predict.parts=[0]", f"paths.models={cfg.paths.models}")  # fmt: skip
    run_predict_part(one, 0)
    whole = run_predict_named(one)
    for name in ("vertexnet", "nrrtnet"):
        for key, value in results[name].items():
            if key.startswith("test/"):
                assert whole[name][key] == pytest.approx(value, abs=1e-3), key


def test_a_heatmap_is_the_network_output_on_the_rendered_instance(predicted, small_data):
    cfg, _, _ = predicted
    h = read_parts(cfg.paths.heatmaps, [0, 1, 2])
    net, record = load_network(f"{cfg.paths.models}/vertexnet.ckpt")
    shard_id, i = h["keys"][3]
    shard = Shard(small_data / "shards" / f"shard_{shard_id}.npz")
    inst = shard.instance(i)
    image = render_instance(shard.grid(inst["map_index"]), inst["start"], inst["goal"],
                            **record["render"])  # fmt: skip
    with torch.no_grad():
        want = net(torch.from_numpy(image)[None]).softmax(1)[0, 1].numpy()
    np.testing.assert_allclose(h["maps"]["vertexnet"][3].astype(np.float32), want, atol=1e-3)


def test_heatmap_metrics_of_a_perfect_map_put_all_mass_near_the_vertices(small_data):
    from vnrrt.data.datamodule import InstanceDataset

    files = [small_data / "shards" / "shard_0.npz"]
    data = InstanceDataset(files, [0], [[0, 0], [0, 1]], "vertex")
    perfect = np.stack([data[n]["vertices"].numpy().astype(np.float16) for n in range(2)])
    m = heatmap_metrics(perfect, data)
    assert m["mass_near_vertex"] == pytest.approx(1.0)
    assert m["mass_near_vertex_uniform"] < 0.5


def test_bad_parts_and_missing_heatmaps_are_named(predicted, tmp_path):
    cfg, _, _ = predicted
    bad = copy.deepcopy(cfg)
    bad.predict.parts = [0, 2]
    with pytest.raises(ConfigError, match=r"predict.parts=\[0, 2\]"):
        run_predict_part(bad, 0)
    with pytest.raises(ConfigError, match="part 3 is not in predict.parts"):
        run_predict_part(cfg, 3)
    with pytest.raises(HeatmapError, match="nothing.npz does not exist"):
        read_heatmaps(tmp_path / "nothing.npz")
    (tmp_path / "bad.npz").write_bytes(b"not a zip")
    with pytest.raises(HeatmapError, match="bad.npz is not a readable"):
        read_heatmaps(tmp_path / "bad.npz")
