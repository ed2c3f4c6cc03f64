"""Paper-scale wall time per stage for a given number of CPU cores and GPUs, from rates
measured in this run (docs/scaling.md, README "Scaling out").

Measured here, each in the same run:

* labelling: instances/s of one core (``build_shard`` of a few maps, one worker);
* training input: images/s of one data-loader worker (instances rendered from a shard);
* the paper network (ResNet34 DynamicUnet): FLOPs per training image, CPU training
  images/s and inference ms per map; on a CUDA GPU, when there is one, bf16 channels_last
  training and inference images/s;
* planner trials: mean seconds per trial for every (map kind, stop rule, planner) of a
  trial table (default: the last ``dvc repro``'s ``data/quick/trials.csv``); the stricter
  any-angle stop, absent from quick-scale tables, from the ``optimal`` trials times the
  any-angle / A* time ratio of uniform RRT* measured on a few of the table's instances.

Without a GPU the GPU rates are assumptions (``--gpu-train-img-s``, default the target of
1,500 images/s on one H100) and the table says so. The estimate scales each stage linearly
(shards and trials are independent jobs; DDP training assumed linear in GPUs, capped by
the data loader's cores). Example:

    .venv/bin/python benchmarks/bench_paper_scale.py --setups 16:1,64:4
"""

from __future__ import annotations

import argparse
import tempfile
import time
from pathlib import Path

import numpy as np
import pandas as pd
import torch

from bench_training import step_rates  # benchmarks/ is on sys.path when this script runs
from vnrrt.config import compose, section
from vnrrt.data.build import build_shard
from vnrrt.data.config import LabelsConfig
from vnrrt.data.datamodule import InstanceDataset
from vnrrt.data.shards import shard_file
from vnrrt.evaluation.config import EvalConfig
from vnrrt.evaluation.protocol import configurations, trial_counts
from vnrrt.evaluation.table import read_table
from vnrrt.infra.parallel import n_workers
from vnrrt.maps.config import DataConfig
from vnrrt.model import FocalLoss, VertexNet
from vnrrt.names import mask_taus
from vnrrt.planners import PlannerConfig, plan, warmup
from vnrrt.planners.reference import any_angle_length

H100_BF16_DENSE_TFLOPS = 989.0  # NVIDIA H100 SXM datasheet, dense bf16 tensor cores


def label_rate(root: Path, maps: int) -> tuple[float, Path]:
    """Labelled instances/s of one core, and the shard it built (``maps`` paper-size maps)."""
    path = shard_file(root, 0)
    build_shard(path, 0, 0, 1, DataConfig(), LabelsConfig(), workers=1)  # numba warm-up
    start = time.perf_counter()
    counts = build_shard(path, 0, 1, maps, DataConfig(), LabelsConfig(), workers=1)
    return counts["instances"] / (time.perf_counter() - start), path


def loader_rate(shard: Path, n: int) -> float:
    """Training items/s (render, target, masks) of one data-loader worker."""
    data = InstanceDataset([shard], [0], [[0, i] for i in range(n)], "vertex")
    data[0]
    start = time.perf_counter()
    for i in range(n):
        data[i]
    return n / (time.perf_counter() - start)


def network_rates(batch: int, steps: int, device: torch.device) -> dict[str, float]:
    """Training and inference images/s of the paper network on ``device`` (bf16 and
    channels_last on CUDA; :func:`bench_training.step_rates`), and its training GFLOPs per image
    (forward + backward)."""
    from torch.utils.flop_counter import FlopCounterMode

    net = VertexNet("resnet34", weights=None, freeze_encoder=False).to(device)
    with FlopCounterMode(display=False) as flops:
        net(torch.rand(1, 3, 200, 200, device=device)).sum().backward()
    gpu = device.type == "cuda"
    rates = step_rates(net, FocalLoss(gamma=2.0), device, batch=batch, channels_last=gpu,
                       bf16=gpu, steps=steps, infer=True)  # fmt: skip
    return {"train": rates["train"], "infer": rates["infer"],
            "train_gflops": flops.get_total_flops() / 1e9}  # fmt: skip


def trial_seconds(trials: pd.DataFrame) -> pd.Series:
    """Mean seconds per trial by (kind, stop, key); a failed trial counts its budget used."""
    t = trials.copy()
    t["kind"] = np.where(t["map_set"] == "random", "random", "named")
    return t.groupby(["kind", "stop", "key"])["time_to_stop"].mean()


def any_angle_ratio(trials: pd.DataFrame, shards: Path, n: int, seed: int = 0) -> float:
    """Median time to 1% of the any-angle length over median time to 1% of A*, uniform
    RRT*, on ``n`` random instances of the table's shards."""
    from vnrrt.data.reader import Shard

    files = sorted(shards.glob("shard_*.npz"))
    shard = Shard(files[0])
    rng = np.random.default_rng(seed)
    warmup()
    times: dict[str, list[float]] = {"astar": [], "any_angle": []}
    config = PlannerConfig()
    for i in rng.choice(shard.instances("test"), size=n, replace=False):
        inst = shard.instance(int(i))
        grid = shard.grid(inst["map_index"])
        start = tuple(float(v) + 0.5 for v in inst["start"])
        goal = tuple(float(v) + 0.5 for v in inst["goal"])
        refs = {"astar": inst["length"], "any_angle": any_angle_length(grid, start, goal)}
        for name, ref in refs.items():
            r = plan(grid, start, goal, "rrt_star", stop="optimal", reference_length=ref,
                     seed=int(i), config=config)  # fmt: skip
            times[name].append(r.time_to_stop)
    return float(np.median(times["any_angle"]) / np.median(times["astar"]))


def trials_hours(per_trial: pd.Series, ratio: float, cfg) -> tuple[float, int, list[str]]:
    """Core-hours and trial count of the paper protocol (``cfg``: the paper config), and the
    planner configurations whose rate was borrowed."""
    ev = section(cfg, "eval", EvalConfig)
    planner = section(cfg, "planner", PlannerConfig)
    specs = configurations(ev, mask_taus(planner.taus, planner.tau), planner.tau)
    n_inst = {"named": 5, "random": ev.random_maps}
    seconds, count, borrowed = 0.0, 0, set()
    for (kind, stop), per_instance in trial_counts(ev).items():
        for spec in specs:
            key, factor = (kind, stop, spec.text), 1.0
            if key not in per_trial.index and stop == "optimal_any_angle":
                key, factor = (kind, "optimal", spec.text), ratio
            if key not in per_trial.index:  # e.g. a tau not in the table: RRT*'s rate
                borrowed.add(spec.text)
                key = (kind, key[1], "rrt_star")
            n = per_instance * n_inst[kind]
            seconds += n * factor * float(per_trial[key])
            count += n
    return seconds / 3600, count, sorted(borrowed)


def fmt_time(seconds: float) -> str:
    """Seconds as s / min / h / days, two or three significant figures."""
    if seconds < 1:
        return "< 1 s"
    if seconds > 3 * 86400:
        return f"{seconds / 86400:.0f} days"
    if seconds < 120:
        return f"{seconds:.0f} s"
    if seconds < 7200:
        return f"{seconds / 60:.0f} min"
    return f"{seconds / 3600:.1f} h"


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--setups", default="16:1,64:4,256:8",
                   help="target setups CORES:GPUS, comma-separated")  # fmt: skip
    p.add_argument("--gpu-train-img-s", type=float, default=1500.0,
                   help="training images/s of one GPU, when none is here to measure")  # fmt: skip
    p.add_argument("--gpu-infer-img-s", type=float, default=4500.0,
                   help="inference images/s of one GPU, when none is here to measure")  # fmt: skip
    p.add_argument("--trials", default="data/quick/trials.csv", help="merged trial table")
    p.add_argument("--shards", default="data/quick/shards", help="shards of that table")
    p.add_argument("--maps", type=int, default=10, help="maps labelled for the rate")
    args = p.parse_args()
    here = n_workers(0)  # this machine's cores (torch uses them all)
    cfg = compose(["scale=paper"])

    with tempfile.TemporaryDirectory() as tmp:
        labels, shard = label_rate(Path(tmp), args.maps)
        loader = loader_rate(shard, 200)
    cpu = network_rates(batch=2, steps=2, device=torch.device("cpu"))
    if torch.cuda.is_available():
        gpu = network_rates(batch=128, steps=20, device=torch.device("cuda"))
        gpu_train, gpu_infer, gpu_note = gpu["train"], gpu["infer"], "measured here"
    else:
        gpu_train, gpu_infer = args.gpu_train_img_s, args.gpu_infer_img_s
        gpu_note = "ASSUMED (no GPU here): --gpu-train-img-s / --gpu-infer-img-s"
    table = read_table(args.trials)
    ratio = any_angle_ratio(table, Path(args.shards), 8)
    hours, n_trials, borrowed = trials_hours(trial_seconds(table), ratio, cfg)

    instances = len(cfg.scale.shards) * cfg.scale.maps_per_shard * 144
    train_items = instances * cfg.data.train_fraction * cfg.trainer.max_epochs
    eval_maps = (cfg.eval.random_maps + 5) * len(cfg.predict.networks)
    setups = [tuple(int(v) for v in item.split(":")) for item in args.setups.split(",")]

    def stage_seconds(c: int, g: int) -> list[float]:
        """Seconds per stage with ``c`` cores and ``g`` GPUs (``g = 0``: CPU only, torch
        rates scaled from this machine's cores)."""
        feed = loader * max(c - g, 1)  # loader workers: the cores not driving a GPU
        train = min(gpu_train * g, feed) if g else cpu["train"] * c / here
        infer = gpu_infer * g if g else cpu["infer"] * c / here
        return [instances / (labels * c), 2 * train_items / train, eval_maps / infer,
                hours * 3600 / c]  # fmt: skip

    names = ["shard@* (maps, A* labels)", "train_vertexnet + train_nrrtnet",
             "predict@* + predict_named", f"trials@* ({n_trials:,} planner trials)"]  # fmt: skip
    print(f"measured here ({here} cores): labelling {labels:,.0f} instances/s/core; "
          f"data loader {loader:,.0f} images/s/worker; paper network {cpu['train_gflops']:.0f}"
          f" training GFLOPs/image, CPU train {cpu['train']:.2f} img/s, CPU inference "
          f"{1e3 / cpu['infer']:.0f} ms/map; trials: {n_trials:,} at paper counts = "
          f"{hours:.1f} core-hours (any-angle/A* time ratio {ratio:.2f}; rates from "
          f"{args.trials}, {len(table):,} trials)")  # fmt: skip
    need = gpu_train * cpu["train_gflops"] / 1e3
    print(f"GPU: train {gpu_train:,.0f} img/s, inference {gpu_infer:,.0f} img/s per GPU "
          f"({gpu_note}); {gpu_train:,.0f} img/s needs {need:,.0f} TFLOP/s = "
          f"{100 * need / H100_BF16_DENSE_TFLOPS:.0f}% of an H100's dense bf16 peak; one "
          f"GPU needs {gpu_train / loader:.0f} loader workers")  # fmt: skip
    if borrowed:
        print(f"no trials of {borrowed} in the table: RRT*'s rate used for them")
    columns = [(here, 0), *setups]
    table_s = [stage_seconds(c, g) for c, g in columns]
    heads = [f"{c} cores" + (f", {g} GPU" if g else " (this machine)") for c, g in columns]
    print("\n| stage | " + " | ".join(heads) + " |")
    print("| --- |" + " --- |" * len(columns))
    for k, name in enumerate(names):
        print(f"| {name} | " + " | ".join(fmt_time(col[k]) for col in table_s) + " |")
    totals = [sum(col) for col in table_s]
    print("| total | " + " | ".join(fmt_time(t) for t in totals) + " |")
    print("| ratio to this machine | " + " | ".join(f"{totals[0] / t:,.0f}x" for t in totals)
          + " |")  # fmt: skip


if __name__ == "__main__":
    main()
