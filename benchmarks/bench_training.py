"""Training throughput: one subcommand per measurement, each beside a baseline measured in the
same run.

* ``step``: the bare training step (forward, focal loss, backward, AdamW on random 200x200
  batches) and inference ms per map of a VertexNet (``--encoder``/``--width``, default the
  paper's resnet34), on CPU and, when present, a CUDA GPU (bf16 autocast and channels_last
  there; ``--compile``).
* ``settings``: the bare step of each ``conf/model`` network (``--models``) per CPU thread
  count, channels_last and bf16 autocast; the ratio is against all threads, fp32, contiguous
  (the figures behind ``conf/scale/cpu.yaml``).
* ``data``: rendering one training item (shard read, class map, colours, target, label
  masks) per second in this process, and the data loader's images/s for 0..``--max-workers``
  worker processes (quick-scale shards).
* ``loop``: the whole Lightning training loop (shards rendered on the fly, focal loss,
  metrics, optimizer) next to the bare step of the same network on random tensors, the data
  loader alone and inference ms per map; ``--smoke`` builds smoke-scale shards in a
  temporary folder instead of reading the pipeline's.
* ``learning``: learning per CPU-minute: each ``model:target_radius`` VertexNet of
  ``--variants`` is trained (bf16, channels_last, all threads) for the steps its measured
  rate fits into ``--minutes`` (a whole one-cycle schedule), then tested on the first 128
  test instances of the quick shards: interior-vertex AP and recall, and the mass within
  3 px of the interior vertices in multiples of a uniform map's.

``data`` and ``learning`` need the quick-scale shards (``dvc repro manifest``). Without a
mode (``make bench``) every mode runs in turn at its defaults. Examples:

    python benchmarks/bench_training.py step --device cpu --batch 4 --steps 3
    python benchmarks/bench_training.py step --device cuda --batch 256 --steps 20 --compile
    python benchmarks/bench_training.py settings --models vertexnet_tiny,vertexnet_lite
    python benchmarks/bench_training.py loop --smoke --model vertexnet_tiny --batch 8
    python benchmarks/bench_training.py learning --minutes 4 --variants vertexnet_tiny:1
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

BATCH = 8


def _sync(device: torch.device) -> None:
    if device.type == "cuda":
        torch.cuda.synchronize(device)


def _timed(step, device: torch.device, warmup: int, steps: int) -> float:
    """Seconds per call of ``step`` after ``warmup`` untimed calls."""
    for _ in range(warmup):
        step()
    _sync(device)
    start = time.perf_counter()
    for _ in range(steps):
        step()
    _sync(device)
    return (time.perf_counter() - start) / steps


def step_rates(net, loss_fn, device: torch.device, *, batch: int, size: int = 200,
               channels_last: bool = False, bf16: bool = False, warmup: int = 1,
               steps: int = 4, compile: bool = False, infer: bool = False) -> dict:  # fmt: skip
    """Images/s of the bare training step of ``net`` on random ``(batch, 3, size, size)``
    inputs (and, with ``infer``, of inference with a softmax), after ``warmup`` steps."""
    fmt = torch.channels_last if channels_last else torch.contiguous_format
    net = net.to(device, memory_format=fmt)
    model = torch.compile(net) if compile else net
    opt = torch.optim.AdamW(net.parameters(), lr=1e-4)
    x = torch.rand(batch, 3, size, size, device=device).to(memory_format=fmt)
    y = (torch.rand(batch, size, size, device=device) < 0.002).long()
    cast = torch.autocast(device.type, torch.bfloat16) if bf16 else contextlib.nullcontext()

    def train_step() -> None:
        with cast:
            loss = loss_fn(model(x).float(), y)
        opt.zero_grad(set_to_none=True)
        loss.backward()
        opt.step()

    @torch.inference_mode()
    def infer_step() -> None:
        with cast:
            model(x).softmax(1)

    model.train()
    out = {"train": batch / _timed(train_step, device, warmup, steps)}
    if infer:
        model.eval()
        out["infer"] = batch / _timed(infer_step, device, warmup, steps)
    return out


def _devices(name: str) -> list[torch.device]:
    names = [name] if name != "auto" else ["cpu"] + (["cuda"] if torch.cuda.is_available() else [])
    return [torch.device(n) for n in names]


def _label(device: torch.device) -> str:
    return torch.cuda.get_device_name(device) if device.type == "cuda" else "cpu"


def _conf_net(model: str):
    """The network and loss of ``conf/model/<model>.yaml``."""
    from hydra.utils import instantiate

    from vnrrt.config import compose

    cfg = compose([f"model={model}"])
    torch.manual_seed(0)
    return instantiate(cfg.model.net), instantiate(cfg.model.loss)


def run_step(args: argparse.Namespace) -> None:
    """``step`` (module doc)."""
    from vnrrt.model import FocalLoss, VertexNet

    for device in _devices(args.device):
        gpu = device.type == "cuda"
        torch.backends.cudnn.benchmark = gpu
        batch = args.batch or (256 if gpu else 4)
        net = VertexNet(args.encoder, weights=None, freeze_encoder=False,
                        decoder_width=args.width)  # fmt: skip
        r = step_rates(net, FocalLoss(gamma=2.0), device, batch=batch, size=args.size,
                       channels_last=gpu, bf16=gpu, warmup=args.warmup, steps=args.steps,
                       compile=args.compile, infer=True)  # fmt: skip
        params = sum(p.numel() for p in net.parameters())
        print(f"{_label(device)}: {args.encoder} width {args.width} ({params:,} params), batch "
              f"{batch}, {args.size}px, bf16={gpu}, channels_last={gpu}, compile={args.compile}:"
              f" train {r['train']:.1f} img/s, inference {r['infer']:.1f} img/s "
              f"({1e3 / r['infer']:.1f} ms/map)")  # fmt: skip


def run_settings(args: argparse.Namespace) -> dict[str, float]:
    """``settings`` (module doc); returns each model's rate with channels_last and bf16."""
    cores, cpu, rates = os.cpu_count() or 1, torch.device("cpu"), {}
    print(f"bare training step, batch {BATCH}, 200x200 (images/s; ratio vs all threads fp32)")
    for model in args.models.split(","):
        torch.set_num_threads(cores)
        base = step_rates(*_conf_net(model), cpu, batch=BATCH)["train"]
        print(f"  {model}: default ({cores} threads, fp32, contiguous) {base:.1f}")
        settings = [(t, False, False) for t in range(1, cores)]
        settings += [(cores, True, False), (cores, False, True), (cores, True, True)]
        for threads, cl, bf16 in settings:
            torch.set_num_threads(threads)
            r = step_rates(*_conf_net(model), cpu, batch=BATCH, channels_last=cl, bf16=bf16)
            rates[model] = r["train"]  # the last: channels_last and bf16 (conf/scale/cpu.yaml)
            what = f"{threads} threads" + (", channels_last" * cl) + (", bf16" * bf16)
            print(f"  {model}: {what:<36} {r['train']:7.1f}  ({r['train'] / base:.2f}x)")
    torch.set_num_threads(cores)
    return rates


def run_data(args: argparse.Namespace) -> None:
    """``data`` (module doc)."""
    from hydra.utils import instantiate

    from vnrrt.config import compose

    dm = instantiate(compose(["scale=quick"]).train.datamodule, target="vertex", num_workers=0,
                     batch_size=BATCH)  # fmt: skip
    dm.setup("fit")
    data, n = dm.datasets["train"], 200
    start = time.perf_counter()
    for i in range(n):
        data[i]
    print(f"rendering one item: {n / (time.perf_counter() - start):.0f} items/s (1 process)")
    for workers in range(args.max_workers + 1):
        dm.num_workers = workers
        start, seen = time.perf_counter(), 0
        for k, batch in enumerate(dm._loader("train")):
            if k == 1:
                start = time.perf_counter()  # after the workers' start-up
            elif k > 1:
                seen += len(batch["image"])
            if k == 40:
                break
        rate = seen / (time.perf_counter() - start)
        print(f"  data loader, {workers} worker processes: {rate:.0f} images/s")


def run_learning(args: argparse.Namespace) -> None:
    """``learning`` (module doc)."""
    from vnrrt.config import compose
    from vnrrt.pipeline.training import run_train

    print(f"learning per CPU-minute: {args.minutes:g} min of steps each, quick shards, "
          f"batch {BATCH}\n  variant (model:target_radius)  steps  fit s  interior AP  "
          "interior recall  mass x unif")  # fmt: skip
    for variant in args.variants.split(","):
        model, radius = variant.split(":")
        rate = step_rates(*_conf_net(model), torch.device("cpu"), batch=BATCH,
                          channels_last=True, bf16=True)["train"]  # fmt: skip
        steps = max(20, int(args.minutes * 60 * rate / BATCH * 0.85))  # ~15% data + metrics
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
        print(f"  {variant:<30} {m['steps']:>5} {m['fit_seconds']:>6.0f} "
              f"{m['test/interior_ap']:>12.4f} {m['test/interior_recall']:>16.3f} "
              f"{ratio:>11.1f}")  # fmt: skip


def _smoke_data(root: Path) -> list[str]:
    """Smoke-scale shards and manifest in ``root``; returns the path overrides."""
    from vnrrt.config import compose, section
    from vnrrt.data.build import build_shard
    from vnrrt.data.config import LabelsConfig
    from vnrrt.data.manifest import build_manifest
    from vnrrt.data.shards import shard_file
    from vnrrt.maps.config import DataConfig

    cfg = compose(["scale=smoke"])
    data, labels = section(cfg, "data", DataConfig), section(cfg, "labels", LabelsConfig)
    for s in cfg.scale.shards:
        build_shard(shard_file(root, s), s, 0, cfg.scale.maps_per_shard, data, labels, workers=1)
    build_manifest(root, list(cfg.scale.shards), root / "manifest.json")
    return ["scale=smoke", f"paths.shards={root}", f"paths.manifest={root / 'manifest.json'}"]


def _loop_rate(args, overrides: list[str], device: torch.device) -> dict:
    """Images/s of the Lightning loop, of its network's bare step, of the loader alone, and
    inference ms per map, for ``args.model`` on ``device``."""
    import lightning as L
    import numpy as np
    from hydra.utils import instantiate

    from vnrrt.config import compose
    from vnrrt.predict.batch import predict

    gpu = device.type == "cuda"
    cfg = compose([*overrides, f"model={args.model}", "logger.enabled=false",
                   f"train.datamodule.batch_size={args.batch}",
                   f"train.datamodule.num_workers={args.workers}"])  # fmt: skip
    dm = instantiate(cfg.train.datamodule, target="vertex", target_radius=0.0)
    dm.setup("fit")
    net, loss = instantiate(cfg.model.net), instantiate(cfg.model.loss)
    module = instantiate(cfg.train.module, _partial_=True)(net=net, loss=loss)
    seen = []

    class Timer(L.Callback):  # the loop's steps after the warm-up ones
        def on_train_batch_start(self, trainer, pl_module, batch, batch_idx) -> None:
            if batch_idx >= args.warmup:
                _sync(device)
                seen.append((time.perf_counter(), len(batch["image"])))

    trainer = L.Trainer(accelerator="gpu" if gpu else "cpu", devices=1, callbacks=[Timer()],
                        precision="bf16-mixed" if gpu else "32-true", limit_val_batches=0,
                        max_steps=args.warmup + args.steps, logger=False,
                        enable_checkpointing=False, enable_progress_bar=False,
                        enable_model_summary=False)  # fmt: skip
    trainer.fit(module, datamodule=dm)
    _sync(device)
    pipeline = sum(n for _, n in seen) / (time.perf_counter() - seen[0][0])
    bare = step_rates(net, loss, device, batch=args.batch, channels_last=gpu, bf16=gpu,
                      warmup=args.warmup, steps=args.steps)["train"]  # fmt: skip
    start, n = time.perf_counter(), 0
    for batch in dm.train_dataloader():
        n += len(batch["image"])
        if n >= args.batch * args.steps:
            break
    loader = n / (time.perf_counter() - start)
    test = dm.datasets["test"]
    images = np.stack([test[i]["image"].numpy() for i in range(len(test))])
    _, sec = predict(net.eval(), images, args.batch, device)
    params = sum(p.numel() for p in net.parameters())
    return {"pipeline": pipeline, "bare": bare, "loader": loader, "ms": 1e3 * sec, "params": params}


def run_loop(args: argparse.Namespace) -> None:
    """``loop`` (module doc)."""
    with tempfile.TemporaryDirectory() as tmp:
        overrides = _smoke_data(Path(tmp)) if args.smoke else []
        for device in _devices(args.device):
            r = _loop_rate(args, overrides, device)
            print(f"{_label(device)}: {args.model} ({r['params']:,} params), batch {args.batch}:"
                  f" training loop {r['pipeline']:.1f} img/s vs bare network step "
                  f"{r['bare']:.1f} img/s ({r['pipeline'] / r['bare']:.0%}); data loader alone "
                  f"{r['loader']:.0f} img/s; inference {r['ms']:.1f} ms/map")  # fmt: skip


def parser() -> argparse.ArgumentParser:
    """The command line (module doc)."""
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    sub = p.add_subparsers(dest="mode")  # none: every mode in turn, at its defaults
    step = sub.add_parser("step", help="bare step and inference of a VertexNet, CPU/CUDA")
    step.set_defaults(run=run_step)
    step.add_argument("--device", default="auto", help="cpu, cuda or auto (both when there)")
    step.add_argument("--encoder", default="resnet34")
    step.add_argument("--width", type=float, default=1.0, help="decoder_width")
    step.add_argument("--batch", type=int, default=None, help="default: 4 on CPU, 256 on GPU")
    step.add_argument("--size", type=int, default=200)
    step.add_argument("--steps", type=int, default=3)
    step.add_argument("--warmup", type=int, default=1)
    step.add_argument("--compile", action="store_true", help="torch.compile the network")
    settings = sub.add_parser("settings", help="CPU threads, channels_last, bf16 per model")
    settings.set_defaults(run=run_settings)
    settings.add_argument("--models", default="vertexnet_tiny,vertexnet_lite")
    data = sub.add_parser("data", help="rendering and data-loader rates (quick shards)")
    data.set_defaults(run=run_data)
    data.add_argument("--max-workers", type=int, default=2)
    loop = sub.add_parser("loop", help="the Lightning loop against the bare step")
    loop.set_defaults(run=run_loop)
    loop.add_argument("--model", default="vertexnet_tiny", help="a conf/model/ name")
    loop.add_argument("--device", default="auto", help="cpu, cuda or auto (both when there)")
    loop.add_argument("--batch", type=int, default=8)
    loop.add_argument("--workers", type=int, default=0, help="data loader processes")
    loop.add_argument("--steps", type=int, default=6)
    loop.add_argument("--warmup", type=int, default=2)
    loop.add_argument("--smoke", action="store_true", help="build smoke shards in a temp folder")
    learn = sub.add_parser("learning", help="learning per CPU-minute of model variants")
    learn.set_defaults(run=run_learning)
    learn.add_argument("--variants", default="vertexnet_tiny:2,vertexnet_lite:2,vertexnet_tiny:1")
    learn.add_argument("--minutes", type=float, default=4.0)
    return p


MODES = ("step", "settings", "loop", "data", "learning")


def main(argv: list[str] | None = None) -> None:
    args = parser().parse_args(argv)
    logging.getLogger("lightning").setLevel(logging.WARNING)
    print(f"cores: {os.cpu_count()}, torch {torch.__version__}, threads {torch.get_num_threads()}")
    runs = [args] if args.mode else [parser().parse_args([mode]) for mode in MODES]
    for run in runs:
        if run.mode in {"data", "learning"} and not Path("data/quick/manifest.json").is_file():
            raise SystemExit("needs the quick-scale shards: run `dvc repro manifest` first")
        print(f"\n{run.mode}:")
        run.run(run)


if __name__ == "__main__":
    main()
