"""The instances, trials, evaluate and report stages on tiny data with oracle heatmaps written
as prediction parts (no training needed), each run with exactly the parameters its dvc.yaml
entry declares: instances and their exact optima, trial parts and their merge, statistics,
report sections, figures, headline metrics and nested MLflow runs."""

import copy
import json
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from vnrrt.config import compose, restrict, stage_params
from vnrrt.data.build import build_shard
from vnrrt.data.build_named import build_named_maps
from vnrrt.data.config import LabelsConfig
from vnrrt.data.heatmaps import part_file, part_rows, write_heatmaps
from vnrrt.data.instances import Instances
from vnrrt.data.manifest import build_manifest
from vnrrt.data.shards import shard_file
from vnrrt.evaluation.table import SEEDED_COLUMNS, TableError, merge_parts, read_table
from vnrrt.infra.machine import describe
from vnrrt.maps.config import DataConfig
from vnrrt.pipeline.evaluation import run_instances, run_trials_part
from vnrrt.pipeline.paper_comparison import run_evaluate, run_report
from vnrrt.search import path_mask
from vnrrt.studies.paper_comparison.headline import VERDICT_KEYS

NETS = (("vertexnet", "vertex"), ("nrrtnet", "path"))


def view(cfg, stage: str, repo: Path):
    """The parameters stage ``stage`` sees when DVC runs it."""
    return restrict(cfg, stage_params(stage, repo / "dvc.yaml"))


@pytest.fixture(scope="module")
def cfg(tmp_path_factory, repo):
    tmp = tmp_path_factory.mktemp("eval")
    build_shard(shard_file(tmp / "shards", 0), 0, 0, 3, DataConfig(), LabelsConfig(), workers=1)
    build_manifest(tmp / "shards", [0], tmp / "manifest.json")
    build_named_maps(tmp / "named.npz", 200, LabelsConfig())
    over = [
        f"paths.shards={tmp / 'shards'}",
        f"paths.manifest={tmp / 'manifest.json'}",
        f"paths.named_maps={tmp / 'named.npz'}",
        f"paths.instances={tmp / 'inst.npz'}",
        f"paths.heatmaps={tmp / 'heat'}",
        f"paths.trials={tmp / 'trials'}",
        f"paths.trials_table={tmp / 'trials.csv'}",
        f"paths.summary={tmp / 'summary.json'}",
        f"paths.plots={tmp / 'plots'}",
        f"paths.metrics={tmp / 'metrics'}",
        f"paths.report={tmp / 'report.md'}",
        f"paths.figures={tmp / 'figures'}",
        f"paths.paper_tables={repo / 'data/paper/tables.yaml'}",
        f"paths.paper_settings={repo / 'data/paper/settings.yaml'}",
        f"logger.uri=sqlite:///{tmp / 'mlflow.db'}",
        "predict.parts=[0,1]",
        "eval.parts=[0,1,2]",
        "scale=smoke",
        "scale.shards=[0]",
        "eval.named_initial=3",
        "eval.named_optimal=2",
        "eval.random_maps=3",
        "planner.max_seconds=5",
        "workers=1",
        "stats.bootstrap=200",
    ]
    cfg = compose(over)
    run_instances(view(cfg, "instances", repo))
    inst = Instances(cfg.paths.instances)
    for part in (0, 1):  # two parts of oracle "networks": 1 on the target cells, 0.02 elsewhere
        rows = range(len(inst))[part_rows(len(inst), part, 2)]
        maps = {
            net: np.stack(
                [
                    np.where(
                        path_mask(
                            getattr(inst[i], target if target == "path" else "vertices"), (200, 200)
                        ),
                        1.0,
                        0.02,
                    )
                    for i in rows
                ]
            )
            for net, target in NETS
        }
        write_heatmaps(part_file(cfg.paths.heatmaps, part), inst.keys[list(rows)], maps)
    write_network_records(cfg)
    return cfg


def write_network_records(cfg) -> None:
    """What the prediction and training stages would have written: ``predict.json`` (the
    networks' metrics, inference times) and each network's training metrics."""
    Path(cfg.paths.metrics).mkdir(parents=True, exist_ok=True)
    settings = {"radius": 3.0, "tau": 0.5, "ap_radius": 1.0, "endpoint_radius": 3.0}
    networks = {
        "vertexnet": {
            "target": "vertex",
            "ms_per_map": 15.0,
            "test/mass_near_interior": 0.1,
            "test/mass_near_interior_uniform": 0.02,
            "test/interior_ap": 0.12,
        },
        "nrrtnet": {
            "target": "path",
            "ms_per_map": 14.0,
            "test/mass_near_path": 0.2,
            "test/mass_near_path_uniform": 0.05,
        },
    }
    Path(cfg.paths.predict_metrics).write_text(
        json.dumps({"settings": settings, "networks": networks})
    )
    for net, kind in NETS:
        train = {"steps": 3, "batch_size": 4, "train_images": 12, "fit_seconds": 1.5,
                 "network": {"encoder": "resnet18", "params_total": 100, "weights": "none"},
                 "target": {"kind": kind}}  # fmt: skip
        Path(cfg.paths.metrics, f"train_{net}.json").write_text(json.dumps(train))


def test_instances_hold_the_named_maps_then_the_random_test_instances(cfg):
    inst = Instances(cfg.paths.instances)
    assert len(inst) == 5 + 3 and inst.kinds == ["named"] * 5 + ["random"] * 3
    named, random = inst[2], inst[6]
    assert named.map_set == "map_3" and named.map == "narrow_passage" and named.key == (-1, 2)
    assert random.map_set == "random" and random.key[0] == 0 and random.cluster >= 0
    for i in range(len(inst)):
        x = inst[i]
        straight = float(np.hypot(*np.subtract(x.goal, x.start)))
        assert straight - 1e-9 <= x.exact_length <= x.taut_length + 1e-9 <= x.astar_length + 1e-6
        np.testing.assert_allclose(x.exact_path[[0, -1]], [x.start, x.goal])
        assert tuple(x.path[0]) == x.start_cell and tuple(x.path[-1]) == x.goal_cell


def test_trial_parts_merge_into_the_protocol_table(cfg, repo):
    sizes = [run_trials_part(view(cfg, f"trials@{k}", repo), k) for k in cfg.eval.parts]
    summary = run_evaluate(view(cfg, "evaluate", repo))
    table = read_table(cfg.paths.trials_table)
    n_configs = 3 + len({0.5, 0.9, 0.99, cfg.planner.tau})
    paper = n_configs * (5 * (3 + 2 + 2) + 3 * (1 + 1 + 1))
    informed = n_configs * 3 * (1 + 1 + 1)  # each again informed, random instances only
    masked = 3 * (5 * (3 + 2 + 2) + 3 * (1 + 1 + 1))  # two mask variants, the masked control
    assert len(table) == sum(sizes) == paper + informed + masked
    variants = {"m_vnrrt_star@0.5{max}", "m_vnrrt_star@0.5{noends}", "m_vnrrt_star@0.5[nrrtnet]"}
    assert variants <= set(table["key"])
    assert set(table.loc[table["key"].str.endswith("+informed"), "map_set"]) == {"random"}
    assert min(sizes) > 0.2 * max(sizes)  # round robin: parts of similar size
    strict = table[table["stop"] == "optimal_any_angle"].reset_index()
    loose = table[table["stop"] == "optimal"].reset_index()
    assert (strict["reference_length"] < loose["reference_length"]).all()
    assert set(table["map_set"]) == {"map_1", "map_2", "map_3", "map_4", "map_5", "random"}
    assert table["success"].mean() > 0.9
    on_disk = json.loads(Path(cfg.paths.summary).read_text())
    assert on_disk["cells"]["optimal"]["vnrrt_star"]["map_3"]["time_to_stop"]["n"] == 2
    assert summary["claims"]["claims"] == 8 and len(summary["claims"]["rows"]) == 8
    comp = on_disk["over_rrt_star"]["time_to_stop"]["optimal"]["nrrt_star"]["random"]
    assert comp["instances"] == 3 and comp["ci_low"] <= comp["speedup"] <= comp["ci_high"]
    curves = pd.read_csv(f"{cfg.paths.plots}/convergence.csv")
    assert {"stop", "planner", "map_set", "factor", "median_time"} <= set(curves.columns)
    series = pd.read_csv(f"{cfg.paths.plots}/convergence/random.csv")
    assert list(series.columns) == ["planner", "median_time_ms", "cost_ratio"]
    assert series["planner"].nunique() == n_configs + 3


def test_report_stage_writes_report_figures_metrics_and_nested_mlflow_runs(cfg, repo):
    import mlflow

    run_report(view(cfg, "report", repo))
    text = Path(cfg.paths.report).read_text()
    for section in (
        "## The paper's quoted claims",
        "### What the masked claims test",
        "| M-VNRRT* τ=0.5 (max-normalised) |",
        "| M-VNRRT* τ=0.5 [nrrtnet] |",
        "## Settings: this run beside the paper",
        "| Steer step eta (px) | 10 (`planner.eta`) |",
        "| vertexnet (smoke) | resnet18 U-Net",
        "## Optimal path lengths",
        "## Table 3",
        "exact continuous optimum",
        "## Planning time and network inference",
        "Bonferroni",
        "different map: not comparable",
        "| NRRT* | ours |",
        "| M-VNRRT* τ=0.5 | ours |",
        "## Informed sampling",
        "| informed VNRRT* |",
        "## The networks' heatmaps",
        "| vertexnet | test | — | 0.12 |",
    ):
        assert section in text, section
    assert "<br>" not in text
    figs = Path(cfg.paths.figures) / "evaluation"
    for name in (
        "improvement_initial.png",
        "improvement_optimal.png",
        "improvement_optimal_any_angle.png",
        "convergence.png",
    ):
        assert (figs / name).stat().st_size > 5000
    headline = json.loads((Path(cfg.paths.metrics) / "headline.json").read_text())
    counted = sum(headline[k] for k in VERDICT_KEYS.values())
    assert counted + headline["untestable"] == 8  # one verdict per testable claim
    assert set(headline["opt_ms"]) == {"rrt", "nrrt", "vnrrt", "m"}  # M-VNRRT* at planner.tau
    summary = json.loads(Path(cfg.paths.summary).read_text())
    m = summary["cells"]["optimal"][f"m_vnrrt_star@{cfg.planner.tau:g}"]["random"]["time_to_stop"]
    assert headline["opt_ms"]["m"] == round(1e3 * m["median"], 3)
    assert headline["mass_x"] == {"vertexnet": 5.0, "nrrtnet": 4.0}
    assert headline["interior_ap"] == {"vertexnet": 0.12}
    assert headline["machine"] == describe()
    mlflow.set_tracking_uri(cfg.logger.uri)
    runs = mlflow.search_runs(experiment_names=[cfg.logger.experiment])
    nested = runs["tags.mlflow.parentRunId"].notna()
    parent = runs[~nested]
    assert len(parent) == 1 and parent["tags.kind"].iloc[0] == "evaluation"
    verdicts = ("reproduced", "same_direction", "no_clear_effect", "reversed")
    counts = [parent[f"metrics.claims/count/{v}"].iloc[0] for v in verdicts]
    assert sum(counts) == 8  # one verdict per claim
    assert "tags.training_run.vertexnet" in parent
    children = runs[nested]
    assert set(children["tags.mlflow.parentRunId"]) == {parent["run_id"].iloc[0]}
    paper = {"rrt_star", "nrrt_star", "vnrrt_star"} | {
        f"m_vnrrt_star@{t:g}" for t in {0.5, 0.9, 0.99, cfg.planner.tau}
    }
    keys = paper | {k + "+informed" for k in paper}  # the informed variants: their own runs
    masked = {"m_vnrrt_star@0.5{max}", "m_vnrrt_star@0.5{noends}", "m_vnrrt_star@0.5[nrrtnet]"}
    assert set(children["tags.planner"]) == keys | masked
    stop = f"within_{100 * cfg.planner.eps:g}pct_of_astar"
    assert children[f"metrics.random_maps/{stop}/success_rate"].notna().all()
    params = children.set_index("tags.planner")
    for key in keys:  # each run's params name its configuration (independent of the key code)
        base = key.removesuffix("+informed")
        planner, _, tau = base.partition("@")
        row = params.loc[key]
        assert row["params.planner"] == planner and row["params.tau"] == (tau or "null")
        assert row["params.informed"] == str(key.endswith("+informed")).lower()
        assert row["params.source"] == cfg.eval.sources.get(planner, "uniform")


def test_the_table_does_not_depend_on_the_split(cfg, repo, tmp_path):
    """One part gives the same trials (all but the timings) as three parts merged."""
    split = read_table(cfg.paths.trials_table)
    one = copy.deepcopy(cfg)
    one.eval.parts, one.paths.trials = [0], str(tmp_path / "one")
    run_trials_part(view(one, "trials@0", repo), 0)
    whole = merge_parts(one.paths.trials, [0], len(split))
    pd.testing.assert_frame_equal(whole[list(SEEDED_COLUMNS)], split[list(SEEDED_COLUMNS)])


def test_missing_repeated_or_foreign_parts_and_heatmaps_are_refused(cfg, repo, tmp_path):
    n = len(read_table(cfg.paths.trials_table))
    with pytest.raises(TableError, match="part_5.csv"):
        merge_parts(cfg.paths.trials, [0, 5], n)
    with pytest.raises(TableError, match="a part is missing, repeated or from another config"):
        merge_parts(cfg.paths.trials, [0, 0, 1, 2], n)
    bad = copy.deepcopy(cfg)
    bad.eval.parts = [1, 2]
    with pytest.raises(Exception, match=r"eval.parts=\[1, 2\]"):
        run_trials_part(view(bad, "trials@1", repo), 1)
    swapped = copy.deepcopy(cfg)  # part 1's file copied over part 0: wrong instances
    swapped.paths.heatmaps = str(tmp_path / "heat")
    (tmp_path / "heat").mkdir()
    part1 = part_file(cfg.paths.heatmaps, 1).read_bytes()
    part_file(tmp_path / "heat", 0).write_bytes(part1)
    part_file(tmp_path / "heat", 1).write_bytes(part1)
    swapped.paths.trials = str(tmp_path / "trials")
    with pytest.raises(ValueError, match="do not cover the instances"):
        run_trials_part(view(swapped, "trials@0", repo), 0)


def _returned_folder(cfg, out: Path) -> Path:
    """What a GPU run (scripts/gpu/paper_network.sh) returns for ``cfg``'s instances, with the
    prediction parts' oracle heatmaps as the paper networks' heatmaps."""
    from vnrrt.data.heatmaps import read_parts
    from vnrrt.data.returned import NETWORKS, write_returned_heatmaps
    from vnrrt.infra.io import sha256

    files = read_parts(cfg.paths.heatmaps, [0, 1])
    maps = {paper: files["maps"][net] for paper, net in NETWORKS.items()}
    kinds = dict(NETS)
    meta = {paper: {"target": {"kind": kinds[net]}, "checkpoint_sha256": "a" * 64,
                    "images_seen": 4096, "train_images_per_s": 900.0,
                    "infer_images_per_s": 3000.0, "batch_size": 64}
            for paper, net in NETWORKS.items()}  # fmt: skip
    write_returned_heatmaps(out, files["keys"], maps, meta, machine="test", budget_s=60)
    source = {"instances_sha256": sha256(cfg.paths.instances)}
    train = {"steps": 64, "batch_size": 64, "train_images": 4096, "fit_seconds": 40.0}
    networks = {p: {"target": m["target"], "train": train} for p, m in meta.items()}
    doc = {"machine": "test", "budget_s": 60, "elapsed_s": 50, "phases": {}, "data": {},
           "probe": {}, "networks": networks, "source": source}  # fmt: skip
    (out / "metrics.json").write_text(json.dumps(doc))
    return out


def test_the_gpu_networks_are_heatmap_sources_of_the_trials(cfg, repo, tmp_path):
    """Issue #27: with eval.gpu, a GPU run's returned heatmaps (read by the returned files'
    reader) are sampled by NRRT*, VNRRT* and M-VNRRT* at planner.tau beside the trained
    networks; the heatmap masses are those of the returned maps. A returned folder made for
    other instances is refused, naming it."""
    from vnrrt.data.returned import ReturnedError

    gpu = copy.deepcopy(cfg)
    gpu.eval.gpu = True
    gpu.paths.gpu_returned = str(_returned_folder(cfg, tmp_path / "returned"))
    gpu.paths.trials = str(tmp_path / "trials")
    run_trials_part(view(gpu, "trials@0", repo), 0)
    table = read_table(Path(gpu.paths.trials) / "part_0.csv")
    tau = cfg.planner.tau
    keys = {"nrrt_star[paper_nrrtnet]", "vnrrt_star[paper_vertexnet]",
            f"m_vnrrt_star@{tau:g}[paper_vertexnet]"}  # fmt: skip
    assert keys <= set(table["key"]), sorted(set(table["key"]))
    per = table.groupby(["key", "instance"])["heat_mass"].first()
    paper, net = per["nrrt_star[paper_nrrtnet]"], per["nrrt_star"]
    both = paper.index.intersection(net.index)
    assert len(both) > 0  # the same maps (both aim at the path): the same masses, per instance
    np.testing.assert_allclose(paper[both], net[both], rtol=1e-6)
    assert per["vnrrt_star[paper_vertexnet]"].notna().all()
    from vnrrt.config import section
    from vnrrt.config.paths import Paths
    from vnrrt.pipeline.paper_comparison import gpu_trainings
    from vnrrt.studies.paper_comparison.disclosure import networks_scale_table

    rows = gpu_trainings(section(gpu, "paths", Paths))  # the report's networks table
    table = networks_scale_table(rows, "smoke", "ResNet34 U-Net")
    assert "| paper_vertexnet (test, a 1-minute run) |" in table and "| 4,096 |" in table
    (tmp_path / "other").mkdir()
    other = _returned_folder(cfg, tmp_path / "other")
    doc = json.loads((other / "metrics.json").read_text())
    doc["source"]["instances_sha256"] = "b" * 64
    (other / "metrics.json").write_text(json.dumps(doc))
    gpu.paths.gpu_returned = str(other)
    with pytest.raises(ReturnedError, match="another instances file"):
        run_trials_part(view(gpu, "trials@0", repo), 0)
