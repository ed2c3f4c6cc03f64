"""The predict stages: float16 heatmaps of every instance of the instances file in parts,
equal to the network's output on the rendered instance and to the one-call
``vnrrt.predict.heatmap``; metrics, inference time kept out of the heatmap files, Fig. 3."""

import copy
import json
from pathlib import Path

import numpy as np
import pytest
import torch

from tests.train_helpers import small_cfg
from vnrrt.config import ConfigError
from vnrrt.data.heatmaps import HeatmapError, part_file, read_heatmaps, read_parts
from vnrrt.data.instances import Instances
from vnrrt.evaluation.instances import build_instances
from vnrrt.maps.render import render_instance
from vnrrt.model.checkpoint import load_network
from vnrrt.pipeline.predict import run_predict_metrics, run_predict_part
from vnrrt.predict import heatmap
from vnrrt.predict.batch import MetricSettings, heatmap_metrics
from vnrrt.search import path_mask

N_RANDOM = 7  # with 5 named maps: 12 instances, not a multiple of the number of parts


@pytest.fixture(scope="module")
def predicted(small_data, trained):
    cfg = small_cfg(small_data, trained, "predict.parts=[0,1,2]", "predict.threads=1")
    build_instances(
        cfg.paths.instances,
        cfg.paths.named_maps,
        [small_data / "shards" / f"shard_{s}.npz" for s in cfg.scale.shards],
        list(cfg.scale.shards),
        N_RANDOM,
        workers=1,
    )
    parts = [run_predict_part(cfg, k) for k in (0, 1, 2)]
    return cfg, parts, run_predict_metrics(cfg)


def test_parts_hold_the_instances_in_order(predicted):
    cfg, parts, _ = predicted
    inst = Instances(cfg.paths.instances)
    sizes = [len(read_heatmaps(part_file(cfg.paths.heatmaps, k))["keys"]) for k in range(3)]
    assert sizes == [4, 4, 4] and len(inst) == 5 + N_RANDOM
    h = read_parts(cfg.paths.heatmaps, [0, 1, 2])
    np.testing.assert_array_equal(h["keys"], inst.keys)
    for name, target in (("vertexnet", "vertex"), ("nrrtnet", "path")):
        maps = h["maps"][name]
        assert maps.shape == (len(inst), 64, 64) and maps.dtype == np.float16
        assert maps.min() >= 0.0 and maps.max() <= 1.0
        assert all(m["networks"][name]["target"]["kind"] == target for m in h["meta"])
        assert all("ms_per_map" not in json.dumps(m) for m in h["meta"])  # timing elsewhere
    assert all(p["vertexnet"] > 0 for p in parts)


def test_metrics_timing_and_figure(predicted):
    cfg, _, out = predicted
    results = out["networks"]
    for name, target in (("vertexnet", "vertex"), ("nrrtnet", "path")):
        assert results[name]["test_instances"] == N_RANDOM and results[name]["ms_per_map"] > 0
        assert 0 <= results[name]["named/mass_near_vertex"] <= 1
        assert results[name]["target"] == target
    saved = json.loads(Path(cfg.paths.predict_metrics).read_text())
    assert set(saved["networks"]) == {"vertexnet", "nrrtnet"}
    assert "test/mass_near_vertex_uniform" in saved["networks"]["vertexnet"]
    taus = sorted({*cfg.planner.taus, cfg.planner.tau})  # the run's thresholds, no others
    assert saved["settings"]["taus"] == taus
    masked = sorted(k for k in saved["networks"]["vertexnet"] if "test/mass_near_interior_tau" in k)
    assert masked == sorted(f"test/mass_near_interior_tau{t:g}".replace(".", "_") for t in taus)
    assert Path(cfg.paths.heatmaps_figure).read_bytes()[:4] == b"\x89PNG"


def test_a_second_prediction_writes_the_same_bytes(predicted):
    cfg, _, _ = predicted
    before = part_file(cfg.paths.heatmaps, 1).read_bytes()
    run_predict_part(cfg, 1)
    assert part_file(cfg.paths.heatmaps, 1).read_bytes() == before


def test_a_heatmap_is_the_network_output_on_the_rendered_instance(predicted):
    cfg, _, _ = predicted
    h = read_parts(cfg.paths.heatmaps, [0, 1, 2])
    ckpt = Path(cfg.paths.models) / "vertexnet.ckpt"
    net, record = load_network(ckpt)
    inst = Instances(cfg.paths.instances)[7]
    image = render_instance(inst.grid, inst.start_cell, inst.goal_cell, **record["render"])
    with torch.no_grad():
        want = net(torch.from_numpy(image)[None]).softmax(1)[0, 1].numpy()
    np.testing.assert_allclose(h["maps"]["vertexnet"][7].astype(np.float32), want, atol=1e-3)
    one_call = heatmap(ckpt, inst.grid, inst.start_cell, inst.goal_cell)
    assert one_call.shape == (64, 64) and one_call.dtype == np.float32
    np.testing.assert_allclose(one_call, want, atol=1e-6)


def test_heatmap_metrics_of_a_perfect_map_put_all_mass_near_the_vertices(predicted):
    cfg, _, _ = predicted
    inst = Instances(cfg.paths.instances)
    rows = [5, 6]
    perfect = np.stack([path_mask(inst[i].vertices, (64, 64)) for i in rows]).astype(np.float16)
    m = heatmap_metrics(perfect, inst, rows, MetricSettings(3.0, 0.5, 1.0, 3.0, (0.5,)))
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
    whole = part_file(cfg.paths.heatmaps, 0).read_bytes()
    (tmp_path / "cut.npz").write_bytes(whole[: len(whole) // 2])  # an interrupted copy
    with pytest.raises(HeatmapError, match="cut.npz is not a readable .npz: File is not a zip"):
        read_heatmaps(tmp_path / "cut.npz")


def test_the_command_line_predicts_what_the_stage_predicted(predicted, tmp_path, capsys):
    """`vnrrt predict` and `vnrrt plan --checkpoint` on a named map give the pipeline's
    heatmap for that instance (row 2 of the parts: named map 3)."""
    from vnrrt.cli.main import load_heatmap, main

    cfg, _, _ = predicted
    ckpt = str(Path(cfg.paths.models) / "vertexnet.ckpt")
    out = tmp_path / "heat.npy"
    named = str(cfg.paths.named_maps)
    assert main(["predict", "--checkpoint", ckpt, "--map", named, "--instance",
                 "narrow_passage", "--out", str(out)]) == 0  # fmt: skip
    want = read_parts(cfg.paths.heatmaps, [0, 1, 2])["maps"]["vertexnet"][2].astype(np.float32)
    np.testing.assert_allclose(np.load(out), want, atol=1e-3)
    png = tmp_path / "heat.png"
    assert main(["predict", "--checkpoint", ckpt, "--map", named, "--instance", "2",
                 "--out", str(png)]) == 0  # fmt: skip
    assert png.read_bytes()[:4] == b"\x89PNG"
    rc = main(["plan", "--map", named, "--instance", "2", "--planner", "vnrrt_star",
               "--checkpoint", ckpt])  # fmt: skip
    assert rc == 0 and "vnrrt_star: success=True" in capsys.readouterr().out
    # A pipeline heatmap file is read at the --map instance's key (-1, 2), in whichever part
    # holds it; a part without it, or a --row of another instance, is refused.
    files = [part_file(cfg.paths.heatmaps, k) for k in cfg.predict.parts]
    holds = [((read_heatmaps(f)["keys"] == (-1, 2)).all(axis=1)).any() for f in files]
    right, wrong = files[holds.index(True)], files[holds.index(False)]
    got = load_heatmap(right, (-1, 2), "vertexnet")
    np.testing.assert_array_equal(got, want.astype(np.float16).astype(np.float64))
    plan = ["plan", "--map", named, "--instance", "2", "--planner", "vnrrt_star", "--network",
            "vertexnet", "--heatmap"]  # fmt: skip
    assert main([*plan, str(right)]) == 0
    assert main([*plan, str(wrong)]) == 2
    assert "holds no heatmap of instance (-1, 2)" in capsys.readouterr().err
    other = int(np.flatnonzero(~(read_heatmaps(right)["keys"] == (-1, 2)).all(axis=1))[0])
    assert main([*plan, str(right), "--row", str(other)]) == 2
    assert "not the --map instance (-1, 2)" in capsys.readouterr().err


def _named_2(cfg):
    """The named-maps file, instance 2 of it (as the CLI reads it) and the heatmap part
    holding that instance."""
    from vnrrt.cli.main import load_instance

    files = [part_file(cfg.paths.heatmaps, k) for k in cfg.predict.parts]
    right = next(f for f in files if ((read_heatmaps(f)["keys"] == (-1, 2)).all(axis=1)).any())
    return str(cfg.paths.named_maps), load_instance(Path(cfg.paths.named_maps), "2"), right


def test_a_pipeline_heatmap_is_refused_for_endpoints_it_was_not_made_for(predicted, capsys):
    """A pipeline heatmap is its instance's, for that instance's own start and goal:
    --start/--goal that move them get a heatmap of other endpoints, which is refused."""
    from vnrrt.cli.main import main

    named, inst, right = _named_2(predicted[0])
    heat = ["plan", "--map", named, "--instance", "2", "--heatmap", str(right), "--network",
            "vertexnet", "--planner", "vnrrt_star"]  # fmt: skip
    swapped = ["--start", "{},{}".format(*inst["goal"]), "--goal", "{},{}".format(*inst["start"])]
    assert main([*heat, *swapped]) == 2
    err = capsys.readouterr().err
    assert "--start/--goal move them: predict one with --checkpoint" in err
    assert err.count("\n") == 1
    same_cells = ["--start", "{},{}".format(*(np.floor(inst["start"]) + 0.25))]
    assert main([*heat, *same_cells]) == 0  # another point of the same start cell: same input


def test_a_network_of_another_target_than_the_planner_samples_is_refused(predicted, capsys):
    """VNRRT* and M-VNRRT* sample vertex heatmaps, NRRT* path heatmaps: the command line
    refuses a checkpoint or a pipeline heatmap of the other network, naming both, and
    vnrrt.predict does given a target."""
    from vnrrt.cli.main import main
    from vnrrt.model.checkpoint import CheckpointError

    cfg, _, _ = predicted
    named, inst, right = _named_2(cfg)
    models = Path(cfg.paths.models)
    base = ["plan", "--map", named, "--instance", "2"]
    heat = [*base, "--heatmap", str(right), "--planner", "nrrt_star", "--network"]
    assert main([*heat, "vertexnet"]) == 2
    err = capsys.readouterr().err
    assert (f"network vertexnet of {right} predicts vertex heatmaps, not the path heatmaps that "
            "--planner nrrt_star samples") in err and err.count("\n") == 1  # fmt: skip
    assert main([*heat, "nrrtnet"]) == 0  # its own network
    capsys.readouterr()
    ckpt = str(models / "nrrtnet.ckpt")
    for planner, extra in (("vnrrt_star", []), ("m_vnrrt_star", ["--tau", "0.5"])):
        assert main([*base, "--planner", planner, "--checkpoint", ckpt, *extra]) == 2
        assert (f"network {ckpt} predicts path heatmaps, not the vertex heatmaps that --planner "
                f"{planner} samples") in capsys.readouterr().err  # fmt: skip
    grid = inst["grid"]
    start, goal = (tuple(int(v) for v in inst[k]) for k in ("start", "goal"))  # their cells
    with pytest.raises(CheckpointError, match="predicts path heatmaps, not the vertex"):
        heatmap(models / "nrrtnet.ckpt", grid, start, goal, target="vertex")
    assert heatmap(models / "nrrtnet.ckpt", grid, start, goal, target="path").shape == grid.shape
