"""Quick timed probes of a GPU run: the largest batch that fits, the data loader's rate,
whether ``torch.compile`` pays, and inference throughput.

Training probes run the real training step (the module's :meth:`model_step`, its loss, its
optimizer, the run's autocast and channels_last) on a fixed batch of real items on the
device, so their rate is the network's alone; :func:`effective_rate` combines it with the
loader's.
"""

from __future__ import annotations

import contextlib
import gc
import logging
import time
from collections.abc import Callable

import torch
from torch.utils.data import DataLoader, Dataset, default_collate

from vnrrt.model.metrics import LABEL_MASKS

log = logging.getLogger(__name__)
MEMORY_FRACTION = 0.85  # a batch fits when the probe's peak stays under this share
TIMED_STEPS = 2  # after one warm-up step


def autocast(device: torch.device, precision: str):
    """The autocast context of a Lightning ``precision`` (bf16-mixed, 16-mixed, or none)."""
    if str(precision).startswith("bf16"):
        return torch.autocast(device.type, dtype=torch.bfloat16)
    if str(precision).startswith("16"):
        return torch.autocast(device.type, dtype=torch.float16)
    return contextlib.nullcontext()


def sync(device: torch.device) -> None:
    if device.type == "cuda":
        torch.cuda.synchronize(device)


def sample_batch(dataset: Dataset, n: int, device: torch.device) -> dict[str, torch.Tensor]:
    """``image`` (n, 3, S, S), ``target`` and the label masks (n, S, S) of the first items of
    ``dataset`` (repeated when it has fewer than ``n``), on ``device``."""
    k, keys = min(n, len(dataset), 64), ("image", "target", *LABEL_MASKS)
    base = default_collate([{key: dataset[i][key] for key in keys} for i in range(k)])
    reps = -(-n // k)
    return {key: v.repeat(reps, *[1] * (v.ndim - 1))[:n].to(device) for key, v in base.items()}


def train_rate(module, batch: dict[str, torch.Tensor], precision: str) -> tuple[float, float]:
    """Images/s of training steps of ``module`` on ``batch`` (:data:`TIMED_STEPS` after one
    warm-up step), the module's training metrics included at its ``train_metrics_every``;
    and the warm-up step's seconds (cuDNN autotuning, compilation)."""
    device = batch["image"].device
    opt = module.optimizer_factory(params=[p for p in module.parameters() if p.requires_grad])
    masks = {k: batch[k] for k in LABEL_MASKS}
    module.train()
    steps, metrics = [], []
    for _ in range(1 + TIMED_STEPS):
        tick = time.perf_counter()
        opt.zero_grad(set_to_none=True)
        with autocast(device, precision):
            loss, probs = module.model_step(batch)
        loss.backward()
        opt.step()
        sync(device)
        mid = time.perf_counter()
        module.train_metrics.update(preds=probs.detach(), target=batch["target"], **masks)
        sync(device)
        steps.append(mid - tick)
        metrics.append(time.perf_counter() - mid)
    module.train_metrics.reset()
    per_step = sum(steps[1:]) + sum(metrics[1:]) / module.train_metrics_every
    return len(batch["image"]) * TIMED_STEPS / per_step, steps[0]


def _on_device(make_module: Callable, device: torch.device):
    module = make_module().to(device)
    module.net.to(memory_format=torch.channels_last)
    return module


def _free(device: torch.device) -> None:
    gc.collect()
    if device.type == "cuda":
        torch.cuda.empty_cache()
        torch.cuda.reset_peak_memory_stats(device)


def probe_batch(make_module: Callable, dataset: Dataset, device: torch.device, precision: str,
                sizes: list[int], deadline: float) -> dict:  # fmt: skip
    """Train-step rate at each batch size of ``sizes`` (ascending) until one runs out of
    memory, passes :data:`MEMORY_FRACTION` of the device, or ``deadline`` (perf_counter)
    passes; ``batch``: the largest that fitted, with its ``images_per_s``."""
    total = torch.cuda.get_device_properties(device).total_memory if device.type == "cuda" else 0
    rows = []
    for b in sizes:
        if rows and time.perf_counter() > deadline:
            break
        _free(device)
        try:
            rate, first = train_rate(_on_device(make_module, device),
                                     sample_batch(dataset, b, device), precision)  # fmt: skip
        except torch.cuda.OutOfMemoryError:
            rows.append({"batch": b, "oom": True})
            break
        peak = torch.cuda.max_memory_allocated(device) if total else 0
        rows.append({"batch": b, "images_per_s": rate, "first_step_s": first,
                     "peak_gib": peak / 2**30})  # fmt: skip
        log.info("probe batch %d: %.0f images/s, peak %.1f GiB", b, rate, peak / 2**30)
        if total and peak > MEMORY_FRACTION * total:
            break
    _free(device)
    fits = [r for r in rows if not r.get("oom") and r["peak_gib"] * 2**30 <= MEMORY_FRACTION
            * (total or float("inf"))]  # fmt: skip
    if not fits:
        raise RuntimeError(f"no batch size of {sizes} fits on {device}: {rows}")
    return {"sizes": rows, "batch": fits[-1]["batch"], "images_per_s": fits[-1]["images_per_s"]}


def loader_rate(dataset: Dataset, batch: int, workers: int, seconds: float) -> float:
    """Images/s the training data loader yields with ``workers`` processes, timed after its
    first batch for about ``seconds`` (at least two batches)."""
    loader = DataLoader(dataset, batch_size=batch, shuffle=True, num_workers=workers)
    it = iter(loader)
    next(it)
    tick, images, n = time.perf_counter(), 0, 0
    for b in it:
        images, n = images + len(b["image"]), n + 1
        if n >= 2 and time.perf_counter() - tick > seconds:
            break
    rate = images / max(time.perf_counter() - tick, 1e-9)
    del it, loader
    return rate


def effective_rate(gpu: float, loader: float, workers: int) -> float:
    """Training images/s: the slower of network and loader when workers run beside the
    network, both in turn (``1 / (1/gpu + 1/loader)``) when the loader shares its process."""
    return min(gpu, loader) if workers > 0 else 1.0 / (1.0 / gpu + 1.0 / loader)


def compile_pays(eager: float, compiled: float, compile_s: float, loader: float,
                 workers: int, seconds: float) -> bool:  # fmt: skip
    """Whether ``seconds`` of training see more images compiled (``compile_s`` spent first)
    than eager, at the :func:`effective_rate` of each."""
    gain = (seconds - compile_s) * effective_rate(compiled, loader, workers)
    return gain > seconds * effective_rate(eager, loader, workers)


def probe_compiled(make_module: Callable, dataset: Dataset, device: torch.device,
                   precision: str, batch: int) -> tuple[float, float]:  # fmt: skip
    """Images/s of compiled training steps at ``batch`` and the compiling step's seconds."""
    _free(device)
    module = _on_device(make_module, device)
    module.compile_training()
    rate, first = train_rate(module, sample_batch(dataset, batch, device), precision)
    del module
    _free(device)
    return rate, first


@torch.inference_mode()
def infer_rate(net: torch.nn.Module, images: torch.Tensor, precision: str, steps: int = 5) -> float:
    """Images/s of ``net`` in eval mode on ``images`` ``(B, 3, S, S)`` (on its device,
    channels_last, the run's autocast), timed over ``steps`` after one warm-up."""
    net.eval()
    x = images.contiguous(memory_format=torch.channels_last)
    times = []
    for _ in range(1 + steps):
        tick = time.perf_counter()
        with autocast(x.device, precision):
            net(x).float().softmax(dim=1)
        sync(x.device)
        times.append(time.perf_counter() - tick)
    return len(x) * steps / sum(times[1:])
