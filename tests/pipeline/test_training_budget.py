"""The budget curve (issue 24): a budget of N steps is a whole training of N steps (its own
one-cycle schedule, run to its end; that the budget of a training's own steps is that
training: the slow DVC test in tests/pipeline/test_pipeline.py), its heatmap metrics are those of
stage ``predict_metrics`` on the same checkpoint (and a uniform map's are what a uniform map
gives), and a smoke-sized curve (64x64 maps, budgets of 2 and 4 steps) renders its table,
trends and figures from paired trials, at two training seeds (pooled, and the claims read
over the seeds)."""

import json
import math
import shutil
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import torch

from tests.stage_closure import REPO
from tests.train_helpers import QUICK, small_cfg
from vnrrt.config import ConfigError, compose, restrict, stage_params
from vnrrt.data.instances import Instances
from vnrrt.data.targets import label_masks
from vnrrt.evaluation.instances import build_instances
from vnrrt.evaluation.table import SEEDED_COLUMNS, read_table
from vnrrt.model.checkpoint import read_checkpoint
from vnrrt.pipeline.budget_training import run_budget_train
from vnrrt.pipeline.predict import run_predict_metrics, run_predict_part
from vnrrt.pipeline.training_budget import (
    run_budget_predict,
    run_budget_report,
    run_budget_trials,
)
from vnrrt.pipeline.validate import validate_config
from vnrrt.studies.training_budget.budget import batches_per_epoch
from vnrrt.studies.training_budget.summary import TEST

N_RANDOM = 6
# The settings a reader sees, none at its default: the report and figures must name these.
ABLATION = ["planner.eps=0.05", "stats.level=0.9", "planner.tau=0.6", "planner.taus=[0.3,0.7]"]
DEFAULTS = ("within 1%", "1% of", "95%", "eps 0.01", "τ=0.5", "τ=0.99", "tau0_5")
BUDGETS = [2, 4]
SEEDS = [0, 1]
NETWORKS = ("vertexnet", "nrrtnet")
# 2 epochs of 2 batches for the pipeline's training (4 steps: the budget of 4); a one-cycle
# schedule needs pct_start x steps != 1; one thread, so that equal settings give equal bytes.
CURVE = [
    *QUICK,
    "trainer.max_epochs=2",
    "train.module.scheduler.pct_start=0.3",
    "train.threads=1",
    "predict.threads=1",
    "predict.parts=[0]",
    "workers=1",
    "budget.steps=[2,4]",
    "budget.seeds=[0,1]",
    "budget.report=[training_budget]",
    "stats.bootstrap=200",
    *ABLATION,
]


def _instances(cfg, small_data) -> None:
    files = [small_data / "shards" / f"shard_{s}.npz" for s in cfg.scale.shards]
    build_instances(
        cfg.paths.instances,
        cfg.paths.named_maps,
        files,
        list(cfg.scale.shards),
        N_RANDOM,
        workers=1,
    )


def _reference_lr(cfg, steps: int, taken: int) -> float:
    """The learning rate of a fresh one-cycle schedule of ``steps`` after ``taken`` steps."""
    sched = cfg.train.module.scheduler
    opt = torch.optim.AdamW([torch.zeros(1, requires_grad=True)], lr=1.0)
    one = torch.optim.lr_scheduler.OneCycleLR(
        opt, max_lr=sched.max_lr, pct_start=sched.pct_start, total_steps=steps
    )
    for _ in range(taken):
        opt.step()
        one.step()
    return opt.param_groups[0]["lr"]


def test_budgets_that_do_not_divide_into_the_epochs_or_lack_a_report_are_refused():
    with pytest.raises(
        ConfigError,
        match=r"budget.steps=5: each budget must be a multiple of "
        r"trainer.max_epochs=2",
    ):
        batches_per_epoch(5, 2)
    cfg = compose(["scale=cpu", "budget.steps=[600,1000]"])
    with pytest.raises(ConfigError, match="budget.steps=1000"):
        validate_config(cfg)
    for bad, message in (
        (["budget.report=[]"], "budget.report=\\[\\]"),
        (["budget.steps=[1200,600]"], "ascending"),
    ):
        with pytest.raises(ConfigError, match=message):
            validate_config(compose(["scale=cpu", *bad]))
    assert compose(["scale=cpu"]).budget.steps == [600, 1200, 2400, 4800]
    assert compose([]).budget.steps == [] and compose(["scale=smoke"]).budget.report == []


def _interior_share(cfg) -> float:
    """Interior-vertex pixels (dilated by the AP radius) among the pixels the interior AP
    counts (all but the start/goal disks off them), pooled over the random instances."""
    from vnrrt.data.targets import dilate

    inst, pos, counted = Instances(cfg.paths.instances), 0, 0
    ap_r, end_r = cfg.predict.metric_ap_radius, cfg.predict.metric_endpoint_radius
    for i in np.flatnonzero(np.array(inst.kinds) == "random"):
        e = inst[int(i)]
        masks = label_masks(e.path, e.vertices, e.grid.shape)
        target = dilate(masks["interior"], ap_r)
        keep = ~dilate(masks["endpoints"], end_r) | target
        pos, counted = pos + int(target[keep].sum()), counted + int(keep.sum())
    return pos / counted


def _view(cfg, stage: str):
    """``cfg`` as DVC gives it to ``stage``: its declared parameters only."""
    return restrict(cfg, stage_params(stage, REPO / "dvc.yaml"))


@pytest.fixture(scope="module")
def curve(small_data, tmp_path_factory):
    """The curve end to end on the 64x64 data through the stages' entry points, each seeing
    its declared parameters only: budgets of 2 and 4 steps over 2 epochs (1 and 2 batches
    each) at training seeds 0 and 1, both networks, their heatmaps, the trials and the report;
    then budget 4's seed-0 networks through the pipeline's predict@0 and predict_metrics.
    Returns the config and the summary."""
    out = tmp_path_factory.mktemp("curve")
    cfg = small_cfg(small_data, out, *CURVE)
    _instances(cfg, small_data)
    before = torch.get_num_threads()
    try:
        for steps in BUDGETS:
            for seed in SEEDS:
                run = f"{steps}-{seed}"
                for name in NETWORKS:
                    run_budget_train(_view(cfg, f"budget_train@{name}-{run}"), name, steps, seed)
                run_budget_predict(_view(cfg, f"budget_predict@{run}"), steps, seed)
                run_budget_trials(_view(cfg, f"budget_trials@{run}"), steps, seed)
    finally:
        torch.set_num_threads(before)
    summary = run_budget_report(_view(cfg, "budget_report@training_budget"), "training_budget")
    models = Path(cfg.paths.models)  # budget 4's networks as the pipeline's, for predict_metrics
    for name in NETWORKS:
        for suffix in (".ckpt", ".ckpt.sha256"):
            shutil.copy(models / f"budget/4-0/{name}{suffix}", models / f"{name}{suffix}")
    try:
        run_predict_part(_view(cfg, "predict@0"), 0)
    finally:
        torch.set_num_threads(before)
    run_predict_metrics(_view(cfg, "predict_metrics"))
    return cfg, summary


def test_a_budget_of_n_steps_is_a_whole_training_of_n_steps(curve):
    """Each budget ends at its step with a schedule sized to it and run to its end (the rate
    of its last step is the schedule's final value, not that of a longer schedule cut short).
    That the budget of a training's own steps is that training:
    tests/pipeline/test_pipeline.py (slow)."""
    cfg, summary = curve
    models = Path(cfg.paths.models)
    for b, seed in ((b, seed) for b in summary["budgets"] for seed in SEEDS):
        steps = b["steps"]
        run = b["networks"]["vertexnet"]["train"][str(seed)]["budget"]
        assert run == {
            "steps": steps,
            "epochs": 2,
            "batches_per_epoch": steps // 2,
            "schedule_steps": steps,
            "schedule_total": steps,
        }
        ckpt = read_checkpoint(models / f"budget/{steps}-{seed}/vertexnet.ckpt")
        sched = ckpt["lr_schedulers"][0]
        assert ckpt["global_step"] == steps and sched["total_steps"] == sched["last_epoch"] == steps
        saved = ckpt["optimizer_states"][0]["param_groups"][0]
        assert saved["lr"] == pytest.approx(_reference_lr(cfg, steps, steps))
        last = _reference_lr(cfg, steps, steps - 1)  # the rate of the last optimizer step
        assert last == pytest.approx(saved["min_lr"]) and last < _reference_lr(cfg, 8, steps - 1)
        assert b["images"] == steps * cfg.train.datamodule.batch_size
        assert not (models / f"budget/{steps}-{seed}/checkpoints/vertexnet").exists()  # cleaned


def test_each_training_seed_trains_other_weights(curve):
    """Seeds 0 and 1 of one budget: the same settings but the seed, other weights."""
    cfg, _ = curve
    models = Path(cfg.paths.models)
    for name in NETWORKS:
        sums = {(models / f"budget/4-{s}/{name}.ckpt.sha256").read_text() for s in SEEDS}
        assert len(sums) == 2, name


def test_the_summary_carries_each_trainings_test_split_metrics(curve):
    """Each seed's training at each budget: its test-split metrics in the summary (the
    networks table of docs/results.md reads them), as its training wrote them."""
    cfg, summary = curve
    for b, name, seed in ((b, n, s) for b in summary["budgets"] for n in NETWORKS for s in SEEDS):
        path = Path(cfg.paths.budget) / f"{b['steps']}-{seed}/train_{name}.json"
        wrote = json.loads(path.read_text())
        kept = b["networks"][name]["train"][str(seed)]
        assert {k: kept[k] for k in TEST} == {k: wrote[k] for k in TEST}


def test_a_budget_stage_measures_its_heatmaps_as_predict_metrics_does(curve):
    """Budget 4's seed-0 networks through budget_predict@4-0, and through predict@0 and
    predict_metrics: the same metrics, settings and targets (all but the inference time)."""
    cfg, _ = curve
    got = json.loads((Path(cfg.paths.budget) / "4-0/predict.json").read_text())
    want = json.loads(Path(cfg.paths.predict_metrics).read_text())
    assert got["settings"] == want["settings"] and set(got["networks"]) == set(NETWORKS)
    for name in NETWORKS:
        a, b = (
            {k: v for k, v in r["networks"][name].items() if k != "ms_per_map"} for r in (got, want)
        )
        assert a == b, name


def test_a_uniform_map_measures_as_a_uniform_map(curve):
    """A budget's uniform-map metrics are the pipeline's own uniform shares (computed apart
    by :class:`vnrrt.model.metrics.MassNear`), and its interior AP is the share of
    interior-vertex pixels among the pixels counted (an AP's chance level). That the networks'
    metrics are predict_metrics': the test above."""
    cfg, _ = curve
    got = json.loads((Path(cfg.paths.budget) / "4-0/predict.json").read_text())
    uniform, network = got["uniform"], got["networks"]["vertexnet"]
    for key in ("mass_near_interior", "mass_near_path", "mass_near_vertex"):
        assert uniform[f"test/{key}"] == pytest.approx(network[f"test/{key}_uniform"], rel=1e-5)
    assert uniform["test/interior_ap"] == pytest.approx(_interior_share(cfg), rel=1e-5)
    assert set(uniform) == {k for k in network if k.startswith(("test/", "named/"))}


def test_the_budgets_share_instances_and_seeds(curve):
    """Every budget and training seed runs the same trials of RRT* on the random maps (the
    same rows), the largest budget the named maps' too; each network's rows carry its
    training seed (``network_seed``), RRT*'s -1."""
    cfg, _ = curve
    runs = [(steps, seed) for steps in BUDGETS for seed in SEEDS]
    tables = [read_table(f"{cfg.paths.budget}/{a}-{b}/trials.csv") for a, b in runs]
    named = set(Instances(cfg.paths.instances).named())
    for (steps, _), t in zip(runs, tables, strict=True):
        largest = steps == max(BUDGETS)
        assert named and set(t["map_set"]) == {"random", *(named if largest else ())}
        assert set(t["stop"]) == {"initial", "optimal", "optimal_any_angle"}
        assert sorted(set(t["key"])) == sorted(
            ["rrt_star", "nrrt_star", "vnrrt_star", f"m_vnrrt_star@{cfg.planner.tau:g}"]
        )
    # every seeded column but the row number (the named maps' rows come first where they run)
    cols = [c for c in SEEDED_COLUMNS if not c.startswith(("heat_", "mass_")) and c != "seq"]
    rrt = [t[(t["key"] == "rrt_star") & (t["map_set"] == "random")][cols].reset_index(drop=True)
           for t in tables]  # fmt: skip
    for other in rrt[1:]:
        pd.testing.assert_frame_equal(rrt[0], other)  # uniform sampling: the same trials
    for (_, seed), t in zip(runs, tables, strict=True):
        want = np.where(t["source"] == "", -1, seed)
        np.testing.assert_array_equal(t["network_seed"].to_numpy(), want)


def _trend(summary: dict, stop: str, metric: str) -> dict:
    (t,) = [t for t in summary["trends"]
            if (t["base"], t["planner"], t["stop"], t["metric"])
            == ("rrt_star", "vnrrt_star", stop, metric)]  # fmt: skip
    return t


def test_the_ratio_to_nrrt_is_the_ratio_of_the_speedups_and_the_trend_its_slope(curve):
    """With one trial per instance the paired VNRRT*/NRRT* ratio is exactly the quotient of
    the two speed-ups over RRT*, per seed and pooled over the seeds (the same instances: the
    pooled log ratio is the mean of the seeds'); with two budgets each seed's factor per
    doubling is the quotient of its budgets' speed-ups raised to 1 / log2(images ratio), and
    the factor shown is their geometric mean."""
    _, summary = curve
    b0, b1 = summary["budgets"]
    images = b1["images"] / b0["images"]
    for stop in summary["settings"]["stops"]:
        for metric in summary["metrics"]:
            for b in (b0, b1, *b0["per_seed"], *b1["per_seed"]):
                s, r = b["speedups"][stop][metric], b["ratios"][stop][metric]
                want = s["vnrrt_star"]["speedup"] / s["nrrt_star"]["speedup"]
                assert r["vnrrt_star"]["speedup"] == pytest.approx(want, rel=1e-9)
            for b in (b0, b1):
                seeds = [
                    p["speedups"][stop][metric]["vnrrt_star"]["speedup"] for p in b["per_seed"]
                ]
                pooled = b["speedups"][stop][metric]["vnrrt_star"]
                assert pooled["speedup"] == pytest.approx(math.exp(np.mean(np.log(seeds))))
                assert pooled["ci_low"] <= pooled["speedup"] <= pooled["ci_high"]
            t, factors = _trend(summary, stop, metric), []
            for k, seed in enumerate(SEEDS):
                one_b0, one_b1 = (b["per_seed"][k]["speedups"][stop][metric] for b in (b0, b1))
                quotient = one_b1["vnrrt_star"]["speedup"] / one_b0["vnrrt_star"]["speedup"]
                one = t["per_seed"][str(seed)]
                assert one["per_doubling"] == pytest.approx(quotient ** (1 / math.log2(images)))
                assert one["ci_low"] <= one["per_doubling"] <= one["ci_high"]
                factors.append(one["per_doubling"])
            assert t["per_doubling"] == pytest.approx(math.exp(np.mean(np.log(factors))))
            seen = {v["verdict"] for v in t["per_seed"].values()}
            assert t["verdict"] == (seen.pop() if len(seen) == 1 else "differs between seeds")


def test_the_claims_over_seeds_pool_each_seeds_own_reading(curve):
    """At the largest budget every claim the budget trials can read (random and named maps)
    is read, those off the random maps marked not comparable: the pooled estimate is the
    geometric mean of the seeds' own (paired on the same instances), each seed's own equals
    the paired comparison of that seed's trials alone, and the interval is at the level
    corrected over the claims read."""
    import yaml

    cfg, summary = curve
    c, paper = summary["claims"], yaml.safe_load((REPO / "data/paper/tables.yaml").read_text())
    masked = f"m_vnrrt_star@{cfg.planner.tau:g}"  # 0.6 here: the paper's tau-0.5 claims unread
    sets = {"random", *Instances(cfg.paths.instances).named()}
    want = [k["text"] for k in paper["claims"] if k["column"] in sets
            and ("@" not in k["planner"] or k["planner"] == masked)]  # fmt: skip
    assert c["seeds"] == SEEDS and [r["text"] for r in c["rows"]] == want and len(want) == 4
    assert c["corrected_level"] == pytest.approx(1 - (1 - cfg.stats.level) / 4)
    for row in c["rows"]:
        assert row["comparable"] == (row["column"] == "random")
        for metric in ("time_to_stop", "iterations"):
            pooled = row["pooled"][metric]
            own = [row["per_seed"][str(s)][metric]["speedup"] for s in SEEDS]
            assert pooled["speedup"] == pytest.approx(math.exp(np.mean(np.log(own))))
            assert pooled["ci_low"] <= pooled["speedup"] <= pooled["ci_high"]
            for s, v in zip(SEEDS, own, strict=True):
                assert pooled["per_seed_point"][str(s)] == pytest.approx(v)


def test_the_curve_renders_its_report_and_figures(curve):
    from PIL import Image

    cfg, summary = curve
    assert [b["images"] for b in summary["budgets"]] == [8, 16]  # 2 and 4 steps of 4 images
    text = Path(cfg.paths.budget_report).read_text()
    eps, level = f"within {100 * cfg.planner.eps:g}% of A*", f"{100 * cfg.stats.level:g}%"
    for piece in (
        "## What the curve says",
        "## The paper's claims over training seeds",
        "training seeds 0, 1",
        "## Training",
        "in multiples of a uniform map",
        "## Trends over the images seen",
        "Over 8 to 16 training images",
        "1,008,000",
        eps,
        level,
        "2 of 2",
        "4 of 4",
        f"M-VNRRT* τ={cfg.planner.tau:g} / NRRT*",
        "figures/budget/speedup_",
    ):
        assert piece in text, piece
    for b in summary["budgets"]:
        assert f"| {b['images']:,} | vertexnet |" in text
    assert not [d for d in DEFAULTS if d in text] and "τ=0.7 mask" in text
    for metric in summary["metrics"]:
        png = cfg.paths.budget_figures + f"/speedup_{metric}.png"
        with Image.open(png) as img:
            said = img.text["Description"]
        assert f"{level} CI" in said and eps in said and "training images seen" in said
        assert not [d for d in DEFAULTS if d in said]
    saved = json.loads(Path(cfg.paths.budget_summary).read_text())
    assert saved["settings"]["level"] == cfg.stats.level and len(saved["trends"]) == 3 * 2 * 5
