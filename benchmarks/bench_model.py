"""VertexNet throughput: training images/s (forward + focal loss + backward + AdamW step) and
inference milliseconds per 200x200 map, on CPU and, when present, on a CUDA GPU.

GPU runs use channels_last and bf16 autocast (the issue's target: >= 1,500 training images/s for
the paper network on one H100). Examples:

    .venv/bin/python benchmarks/bench_model.py --device cpu --batch 4 --steps 3
    .venv/bin/python benchmarks/bench_model.py --device cuda --batch 256 --steps 20 --compile
"""

from __future__ import annotations

import argparse
import contextlib
import time

import torch

from vnrrt.model import FocalLoss, VertexNet


def _sync(device: torch.device) -> None:
    if device.type == "cuda":
        torch.cuda.synchronize(device)


def _autocast(device: torch.device, bf16: bool) -> contextlib.AbstractContextManager:
    if bf16:
        return torch.autocast(device.type, dtype=torch.bfloat16)
    return contextlib.nullcontext()


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


def bench(args: argparse.Namespace, device: torch.device) -> dict[str, float]:
    """Train and inference timings of one network configuration on ``device``."""
    fmt = torch.channels_last if args.channels_last else torch.contiguous_format
    net = VertexNet(args.encoder, weights=None, freeze_encoder=False, decoder_width=args.width)
    net = net.to(device, memory_format=fmt)
    model = torch.compile(net) if args.compile else net
    loss_fn, opt = FocalLoss(gamma=2.0), torch.optim.AdamW(net.parameters(), lr=1e-4)
    x = torch.rand(args.batch, 3, args.size, args.size, device=device).to(memory_format=fmt)
    y = (torch.rand(args.batch, args.size, args.size, device=device) < 0.01).long()

    def train_step() -> None:
        with _autocast(device, args.bf16):
            loss = loss_fn(model(x), y)
        opt.zero_grad(set_to_none=True)
        loss.backward()
        opt.step()

    @torch.inference_mode()
    def infer_step() -> None:
        with _autocast(device, args.bf16):
            model(x).softmax(1)

    model.train()
    train_s = _timed(train_step, device, args.warmup, args.steps)
    model.eval()
    infer_s = _timed(infer_step, device, args.warmup, args.steps)
    return {
        "train_images_per_s": args.batch / train_s,
        "infer_images_per_s": args.batch / infer_s,
        "infer_ms_per_map": 1e3 * infer_s / args.batch,
        "params": sum(p.numel() for p in net.parameters()),
    }


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--device", default="auto", help="cpu, cuda or auto (both when available)")
    p.add_argument("--encoder", default="resnet34")
    p.add_argument("--width", type=float, default=1.0, help="decoder_width")
    p.add_argument("--batch", type=int, default=None, help="default: 4 on CPU, 256 on GPU")
    p.add_argument("--size", type=int, default=200)
    p.add_argument("--steps", type=int, default=3)
    p.add_argument("--warmup", type=int, default=1)
    p.add_argument("--compile", action="store_true", help="torch.compile the network")
    args = p.parse_args()
    devices = [args.device] if args.device != "auto" else ["cpu"]
    if args.device == "auto" and torch.cuda.is_available():
        devices.append("cuda")
    for name in devices:
        device = torch.device(name)
        run = argparse.Namespace(**vars(args))
        run.batch = args.batch or (256 if device.type == "cuda" else 4)
        run.bf16 = run.channels_last = device.type == "cuda"
        if device.type == "cuda":
            torch.backends.cudnn.benchmark = True
        res = bench(run, device)
        label = torch.cuda.get_device_name(device) if device.type == "cuda" else "cpu"
        print(
            f"{label}: {args.encoder} width {args.width} ({res['params']:,} params), "
            f"batch {run.batch}, {args.size}px, bf16={run.bf16}, channels_last="
            f"{run.channels_last}, compile={args.compile}: train "
            f"{res['train_images_per_s']:.1f} img/s, inference "
            f"{res['infer_images_per_s']:.1f} img/s ({res['infer_ms_per_map']:.1f} ms/map)"
        )


if __name__ == "__main__":
    main()
