"""Stage ``bench_maps@benchmark_maps``: part of the default pipeline (its quick subset, the full
set at the CPU scale, a tiny one at smoke), and a run of its entry function on arena with two
random-weight networks: the outputs it declares, one row per (query, configuration, trial), the
report's pooled speed-up recomputed by hand from the written trial table, rows reused on a
second run, and a missing map named before any work."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
import torch
import yaml

from tests.stage_closure import REPO
from vnrrt.config import compose, restrict, stage_params
from vnrrt.config.paths import Paths, stage_outputs
from vnrrt.evaluation.table import SEEDED_COLUMNS, read_table
from vnrrt.maps.movingai import MovingAIError
from vnrrt.model.checkpoint import NETWORK_CLASS, seal
from vnrrt.model.record import RECORD_KEY
from vnrrt.model.vertexnet import VertexNet
from vnrrt.pipeline.benchmark_maps import run_bench_maps
from vnrrt.pipeline.validate import validate_config
from vnrrt.studies.benchmark_maps.design import read_benchmark, sample_scenarios
from vnrrt.studies.benchmark_maps.report import ratio

STAGE = "bench_maps@benchmark_maps"
SHIPPED = {"arena", "lak304d", "64room_000", "losttemple"}
ENVELOPES = {"path": "nrrt_star~0.5[oracle_path@s1]", "vertex": "vnrrt_star~0.5[oracle_vertex@s4]"}
NET = {"_target_": NETWORK_CLASS, "encoder": "resnet18", "out_channels": 2, "in_channels": 3,
       "decoder_width": 0.25, "encoder_width": 0.25}  # fmt: skip


def test_the_stage_runs_the_quick_subset_in_the_default_pipeline():
    entry = yaml.safe_load((REPO / "dvc.yaml").read_text())["stages"]["bench_maps"]
    assert entry["foreach"] == "${bench_maps.report}"
    assert entry["do"]["cmd"] == "python stages/bench_maps.py --name ${item}"
    default, cpu = compose(), compose(["scale=cpu"])
    assert default.scale.name == "quick" and list(default.bench_maps.report) == ["benchmark_maps"]
    quick = dict(default.bench_maps.maps)
    assert 2 <= len(quick) < len(SHIPPED) and set(quick) <= SHIPPED
    assert set(cpu.bench_maps.maps) == SHIPPED and list(cpu.bench_maps.report) == ["benchmark_maps"]
    for name, buckets in quick.items():  # every bucket of the subset can be drawn
        grid, scen = read_benchmark(REPO / default.paths.movingai, name)
        queries = sample_scenarios(scen, grid, name, list(buckets), default.bench_maps.per_bucket,
                                   int(default.seed))  # fmt: skip
        assert len(queries) == len(buckets) * default.bench_maps.per_bucket
    assert len(compose(["scale=smoke"]).bench_maps.maps) == 1  # a tiny one in the smoke run


def _checkpoint(folder: Path, network: str, kind: str) -> None:
    torch.manual_seed(len(network))
    kwargs = {k: v for k, v in NET.items() if k != "_target_"}
    net = VertexNet(**kwargs, weights=None, freeze_encoder=False).eval()
    record = {"network": network, "net": NET,
              "target": {"kind": kind, "endpoints": "both", "radius": 1.0},
              "render": {"marker_radius": 2.0, "normalize": "imagenet"}}  # fmt: skip
    state = {f"net.{k}": v for k, v in net.state_dict().items()}
    torch.save(seal({"state_dict": state, RECORD_KEY: record}), folder / f"{network}.ckpt")


@pytest.fixture(scope="module")
def cfg(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("bench_maps")
    (tmp / "models").mkdir()
    _checkpoint(tmp / "models", "vertexnet", "vertex")
    _checkpoint(tmp / "models", "nrrtnet", "path")
    ideas = {"selection": {"envelopes": {"optimal_any_angle": ENVELOPES}}}
    (tmp / "ideas.json").write_text(json.dumps(ideas))
    (tmp / "summary.json").write_text("{}")
    over = ["scale=smoke", "planner.eps=0.05", "stats.level=0.9", "stats.bootstrap=200",
            "workers=1", "logger.enabled=false", f"paths.models={tmp / 'models'}",
            f"paths.ideas_summary={tmp / 'ideas.json'}", f"paths.summary={tmp / 'summary.json'}",
            f"paths.reuse={tmp / 'reuse'}", f"paths.bench_maps_trials={tmp / 'bench.csv'}",
            f"paths.bench_maps_summary={tmp / 'bench.json'}",
            f"paths.bench_maps_report={tmp / 'benchmark_maps.md'}",
            f"paths.movingai={REPO / 'data/movingai'}"]  # fmt: skip
    return compose(over)


def _run(cfg) -> dict:
    return run_bench_maps(restrict(cfg, stage_params(STAGE, REPO / "dvc.yaml")), "benchmark_maps")


def test_a_run_writes_its_outputs_and_the_report_recomputes_from_its_table(cfg):
    summary = _run(cfg)
    paths = Paths(**cfg.paths)
    for out in stage_outputs("bench_maps", paths, "benchmark_maps"):
        assert Path(out).is_file(), out
    table = read_table(paths.bench_maps_trials)
    keys = ["rrt_star", "nrrt_star", "vnrrt_star", "m_vnrrt_star@0.5", *ENVELOPES.values()]
    assert summary["keys"] == keys
    assert len(table) == 2 * len(keys) * 2 and set(table["stop"]) == {"optimal_any_angle"}
    assert set(table["map_set"]) == {"arena"} and sorted(set(table["cluster"])) == [3, 12]
    ok = table[table["success"]]
    assert (ok["cost"] <= 1.05 * ok["reference_length"] + 1e-9).all()
    med = table.groupby(["key", "instance"])["time_to_stop"].median()
    want = np.exp(np.mean(np.log(med["rrt_star"] / med["vnrrt_star"])))
    (cell,) = [c for c in summary["cells"]
               if (c["map"], c["configuration"]) == ("pooled", "vnrrt_star")]  # fmt: skip
    assert cell["time_to_stop"]["speedup"] == pytest.approx(want)
    text = Path(paths.bench_maps_report).read_text()
    assert ratio(cell["time_to_stop"]) in text and "within 5% of the exact optimum" in text
    assert "90% paired bootstrap" in text and "95%" not in text
    assert summary["maps"]["arena"]["width"] == 49 and summary["maps"]["arena"]["queries"] == 2


def test_a_second_run_reuses_the_kept_rows(cfg):
    paths = Paths(**cfg.paths)
    first = read_table(paths.bench_maps_trials)
    _run(cfg)
    again = read_table(paths.bench_maps_trials)
    assert again[list(SEEDED_COLUMNS)].equals(first[list(SEEDED_COLUMNS)])
    assert again["time_to_stop"].equals(first["time_to_stop"])  # read back, not planned again


def test_a_missing_map_is_named_before_any_work(cfg):
    bad = compose(["scale=smoke", "+bench_maps.maps.nowhere=[1]"])
    with pytest.raises(MovingAIError, match=r"nowhere\.map: no such file"):
        validate_config(bad)
