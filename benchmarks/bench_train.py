"""Training pipeline throughput: images/s of the full Lightning loop (shards rendered on the
fly, focal loss, metrics, optimizer) next to the bare network step on random tensors (the
baseline, measured in the same run), the data loader alone, and inference ms per map.

CPU always; CUDA too when present (bf16-mixed, channels_last, as trainer/gpu.yaml). Uses the
shards of ``paths`` (``dvc repro`` first) or, with ``--smoke``, smoke-scale shards built in a
temporary folder. Examples:

    .venv/bin/python benchmarks/bench_train.py --model vertexnet_tiny --batch 8 --steps 6
    .venv/bin/python benchmarks/bench_train.py --model vertexnet --device cuda --batch 128 \
        --workers 12 --steps 30
"""

from __future__ import annotations

import argparse
import contextlib
import logging
import tempfile
import time
from pathlib import Path

import lightning as L
import numpy as np
import torch
from hydra.utils import instantiate

from vnrrt.config import compose, section
from vnrrt.data.build import build_shard
from vnrrt.data.config import LabelsConfig
from vnrrt.data.manifest import build_manifest
from vnrrt.data.shards import shard_file
from vnrrt.maps.config import DataConfig
from vnrrt.predict.batch import predict


class StepTimer(L.Callback):
    """Wall time of the training steps after ``warmup`` steps."""

    def __init__(self, warmup: int) -> None:
        self.warmup, self.start, self.images = warmup, 0.0, 0

    def on_train_batch_start(self, trainer, pl_module, batch, batch_idx) -> None:
        if batch_idx == self.warmup:
            if pl_module.device.type == "cuda":
                torch.cuda.synchronize()
            self.start = time.perf_counter()
        if batch_idx >= self.warmup:
            self.images += len(batch["image"])

    def rate(self, device: torch.device) -> float:
        if device.type == "cuda":
            torch.cuda.synchronize()
        return self.images / (time.perf_counter() - self.start)


def smoke_data(root: Path) -> list[str]:
    """Smoke-scale shards and manifest in ``root``; returns the path overrides."""
    cfg = compose(["scale=smoke"])
    data, labels = section(cfg, "data", DataConfig), section(cfg, "labels", LabelsConfig)
    for s in cfg.scale.shards:
        build_shard(shard_file(root, s), s, 0, cfg.scale.maps_per_shard, data, labels, workers=1)
    build_manifest(root, list(cfg.scale.shards), root / "manifest.json")
    return ["scale=smoke", f"paths.shards={root}", f"paths.manifest={root / 'manifest.json'}"]


def bench(args: argparse.Namespace, overrides: list[str], device: torch.device) -> dict:
    """Pipeline, baseline, loader and inference figures of one configuration on ``device``."""
    gpu = device.type == "cuda"
    cfg = compose([*overrides, f"model={args.model}", "logger.enabled=false",
                   f"train.datamodule.batch_size={args.batch}",
                   f"train.datamodule.num_workers={args.workers}"])  # fmt: skip
    dm = instantiate(cfg.train.datamodule, target="vertex", target_radius=0.0)
    dm.setup("fit")
    net, loss = instantiate(cfg.model.net), instantiate(cfg.model.loss)
    module = instantiate(cfg.train.module, _partial_=True)(net=net, loss=loss)
    timer = StepTimer(args.warmup)
    trainer = L.Trainer(accelerator="gpu" if gpu else "cpu", devices=1,
                        precision="bf16-mixed" if gpu else "32-true", max_steps=args.warmup
                        + args.steps, limit_val_batches=0, logger=False, callbacks=[timer],
                        enable_checkpointing=False, enable_progress_bar=False,
                        enable_model_summary=False)  # fmt: skip
    trainer.fit(module, datamodule=dm)
    pipeline = timer.rate(device)
    baseline = raw_step_rate(net.to(device), loss, args, device)
    start, n = time.perf_counter(), 0
    for batch in dm.train_dataloader():
        n += len(batch["image"])
        if n >= args.batch * args.steps:
            break
    loader = n / (time.perf_counter() - start)
    data = dm.datasets["test"]
    images = np.stack([data[i]["image"].numpy() for i in range(len(data))])
    _, sec = predict(net.eval(), images, args.batch, device)
    return {"pipeline": pipeline, "baseline": baseline, "loader": loader, "ms_per_map": 1e3 * sec,
            "params": sum(p.numel() for p in net.parameters())}  # fmt: skip


def raw_step_rate(net, loss_fn, args, device: torch.device) -> float:
    """Images/s of forward + focal loss + backward + AdamW on random tensors (no data, no
    Lightning): the baseline the pipeline is compared with."""
    gpu = device.type == "cuda"
    fmt = torch.channels_last if gpu else torch.contiguous_format
    net = net.to(device, memory_format=fmt).train()
    opt = torch.optim.AdamW(net.parameters(), lr=1e-4)
    x = torch.rand(args.batch, 3, 200, 200, device=device).to(memory_format=fmt)
    y = (torch.rand(args.batch, 200, 200, device=device) < 0.001).long()
    autocast = torch.autocast("cuda", torch.bfloat16) if gpu else contextlib.nullcontext()
    for i in range(args.warmup + args.steps):
        if i == args.warmup:
            if gpu:
                torch.cuda.synchronize()
            start = time.perf_counter()
        with autocast:
            loss = loss_fn(net(x), y)
        opt.zero_grad(set_to_none=True)
        loss.backward()
        opt.step()
    if gpu:
        torch.cuda.synchronize()
    return args.batch * args.steps / (time.perf_counter() - start)


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--model", default="vertexnet_tiny", help="a conf/model/ name")
    p.add_argument("--device", default="auto", help="cpu, cuda or auto (both when available)")
    p.add_argument("--batch", type=int, default=8)
    p.add_argument("--workers", type=int, default=0, help="data loader processes")
    p.add_argument("--steps", type=int, default=6)
    p.add_argument("--warmup", type=int, default=2)
    p.add_argument("--smoke", action="store_true", help="build smoke shards in a temp folder")
    args = p.parse_args()
    logging.getLogger("lightning").setLevel(logging.WARNING)
    devices = [args.device] if args.device != "auto" else ["cpu"]
    if args.device == "auto" and torch.cuda.is_available():
        devices.append("cuda")
    with tempfile.TemporaryDirectory() as tmp:
        overrides = smoke_data(Path(tmp)) if args.smoke else []
        for name in devices:
            device = torch.device(name)
            res = bench(args, overrides, device)
            label = torch.cuda.get_device_name(device) if device.type == "cuda" else "cpu"
            print(
                f"{label}: {args.model} ({res['params']:,} params), batch {args.batch}: "
                f"training pipeline {res['pipeline']:.1f} img/s vs bare network step "
                f"{res['baseline']:.1f} img/s ({res['pipeline'] / res['baseline']:.0%}); data "
                f"loader alone {res['loader']:.0f} img/s; inference {res['ms_per_map']:.1f} ms/map"
            )
    if "cuda" not in devices:
        print("no GPU: CUDA figures skipped")


if __name__ == "__main__":
    main()
