"""CPU training: images/s per setting, and learning per CPU-minute of candidate variants.

Measured in one run, on this machine's cores (the figures behind ``conf/scale/cpu.yaml``):

1. The bare training step (forward, focal loss, backward, AdamW on random 200x200 batches)
   per network variant, for each intra-op thread count, ``channels_last`` and bf16 autocast
   on CPU; the ratio is against the default (all threads, fp32, contiguous) measured here.
2. Input rendering (one item of the dataset: shard read, class map, colours, target, label
   masks) per second, and the data loader's images/s for 0..``--max-workers`` processes.
3. Learning per CPU-minute: each candidate ``model:target_radius`` VertexNet is trained
   (bf16-mixed, channels_last, all threads) for the number of steps its measured rate fits
   into ``--minutes`` (a whole one-cycle schedule,
   not a cut one) on the quick-scale shards, then tested on their first 128 test instances:
   interior-vertex AP and recall, and the mass within 3 px of the interior vertices as a
   multiple of a uniform map's.

    python benchmarks/bench_cpu_training.py [--minutes 4] [--variants vertexnet_tiny:2,...]

Needs the quick-scale shards (``dvc repro manifest``).
"""

from __future__ import annotations

import argparse
import contextlib
import logging
import os
import tempfile
import time
from pathlib import Path

import torch
from hydra.utils import instantiate

from vnrrt.config import compose

BATCH = 8


def step_rate(model: str, threads: int, channels_last: bool, bf16: bool, steps: int = 4) -> float:
    """Images/s of the bare training step of conf/model/``model`` (first step not timed)."""
    torch.set_num_threads(threads)
    cfg = compose([f"model={model}"])
    torch.manual_seed(0)
    net, loss_fn = instantiate(cfg.model.net).train(), instantiate(cfg.model.loss)
    fmt = torch.channels_last if channels_last else torch.contiguous_format
    net = net.to(memory_format=fmt)
    opt = torch.optim.AdamW(net.parameters(), lr=1e-4)
    x = torch.rand(BATCH, 3, 200, 200).to(memory_format=fmt)
    y = (torch.rand(BATCH, 200, 200) < 0.002).long()
    cast = torch.autocast("cpu", torch.bfloat16) if bf16 else contextlib.nullcontext()
    for i in range(steps + 1):
        if i == 1:
            start = time.perf_counter()
        with cast:
            loss = loss_fn(net(x).float(), y)
        opt.zero_grad(set_to_none=True)
        loss.backward()
        opt.step()
    return BATCH * steps / (time.perf_counter() - start)


def throughput(models: list[str], cores: int) -> dict[str, float]:
    """Part 1: step rates per (model, threads, channels_last, bf16); returns each model's
    rate with channels_last and bf16 (the setting of part 3)."""
    rates = {}
    print(f"\n1. bare training step, batch {BATCH}, 200x200 (images/s; ratio vs all threads fp32)")
    for model in models:
        base = step_rate(model, cores, False, False)
        print(f"  {model}: default ({cores} threads, fp32, contiguous) {base:.1f}")
        settings = [(t, False, False) for t in range(1, cores)]
        settings += [(cores, True, False), (cores, False, True), (cores, True, True)]
        for threads, cl, bf16 in settings:
            r = step_rate(model, threads, cl, bf16)
            if cl and bf16:
                rates[model] = r  # the setting of part 3 (and of conf/scale/cpu.yaml)
            what = (
                f"{threads} threads"
                + (", channels_last" if cl else "")
                + (", bf16" if bf16 else "")
            )
            print(f"  {model}: {what:<36} {r:7.1f}  ({r / base:.2f}x)")
    torch.set_num_threads(cores)
    return rates


def data_rates(max_workers: int) -> None:
    """Part 2: rendering items/s in this process, and the loader per worker count."""
    cfg = compose(["scale=quick"])
    dm = instantiate(cfg.train.datamodule, target="vertex", num_workers=0, batch_size=BATCH)
    dm.setup("fit")
    data = dm.datasets["train"]
    n = 200
    start = time.perf_counter()
    for i in range(n):
        data[i]
    print(f"\n2. rendering one item: {n / (time.perf_counter() - start):.0f} items/s (1 process)")
    for workers in range(max_workers + 1):
        dm.num_workers = workers
        loader = dm._loader("train")
        start, seen = None, 0
        for k, batch in enumerate(loader):
            if k == 1:
                start = time.perf_counter()  # after the workers' start-up
            elif k > 1:
                seen += len(batch["image"])
            if k == 40:
                break
        rate = seen / (time.perf_counter() - start)
        print(f"  data loader, {workers} worker processes: {rate:.0f} images/s")


def learning(variants: list[str], minutes: float, rates: dict[str, float]) -> None:
    """Part 3: each variant trained for ``minutes`` worth of steps, then tested."""
    from vnrrt.pipeline.training import run_train

    print(
        f"\n3. learning per CPU-minute: {minutes:g} min of steps each, quick shards, batch {BATCH}"
    )
    head = "variant (model:target_radius)  steps  fit s  interior AP  interior recall  mass x unif"
    print("  " + head)
    for variant in variants:
        model, radius = variant.split(":")
        if model not in rates:
            rates[model] = step_rate(model, os.cpu_count() or 1, True, True)
        steps = max(20, int(minutes * 60 * rates[model] / BATCH * 0.85))  # ~15% data + metrics
        with tempfile.TemporaryDirectory() as tmp:
            cfg = compose(["scale=quick", f"model={model}", "logger.enabled=false",
                           f"train.datamodule.target_radius={radius}", "trainer.max_epochs=1",
                           "trainer.precision=bf16-mixed", "train.module.channels_last=true",
                           f"trainer.limit_train_batches={steps}", "trainer.limit_val_batches=0",
                           "train.datamodule.test_instances=128", "callbacks.progress=null",
                           f"paths.models={tmp}/models",
                           f"paths.metrics={tmp}/metrics"])  # fmt: skip
            m = run_train(cfg, "vertexnet")
        ratio = m["test/mass_near_interior"] / max(m["test/mass_near_interior_uniform"], 1e-12)
        ap, recall = m["test/interior_ap"], m["test/interior_recall"]
        print(f"  {variant:<30} {m['steps']:>5} {m['fit_seconds']:>6.0f} "
              f"{ap:>12.4f} {recall:>16.3f} {ratio:>11.1f}")  # fmt: skip


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--models", default="vertexnet_tiny,vertexnet_lite")
    ap.add_argument("--variants", default="vertexnet_tiny:2,vertexnet_lite:2,vertexnet_tiny:1")
    ap.add_argument("--minutes", type=float, default=4.0)
    ap.add_argument("--max-workers", type=int, default=2)
    ap.add_argument("--skip-learning", action="store_true")
    ap.add_argument("--only-learning", action="store_true")
    args = ap.parse_args(argv)
    logging.getLogger("lightning").setLevel(logging.WARNING)
    cores = os.cpu_count() or 1
    print(f"cores: {cores}, torch {torch.__version__}, default threads {torch.get_num_threads()}")
    rates = {} if args.only_learning else throughput(args.models.split(","), cores)
    if not args.only_learning:
        data_rates(args.max_workers)
    if not args.skip_learning:
        learning(args.variants.split(","), args.minutes, rates)


if __name__ == "__main__":
    if not Path("data/quick/manifest.json").is_file():
        raise SystemExit("needs the quick-scale shards: run `dvc repro manifest` first")
    main()
