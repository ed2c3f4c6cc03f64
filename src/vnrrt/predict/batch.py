"""Batch prediction of the evaluation instances and the heatmap metrics.

Inputs are rendered from the instances file (:mod:`vnrrt.data.instances`) exactly as
in training (the checkpoint's record), so prediction needs neither the shards nor a data
loader. Heatmaps are stored as float16 (:mod:`vnrrt.data.heatmaps`).
"""

from __future__ import annotations

import contextlib
import time
from dataclasses import dataclass

import numpy as np
import torch

from vnrrt.data.targets import label_masks
from vnrrt.maps.render import render_instance


def inputs(instances, rows, render: dict) -> np.ndarray:
    """Network inputs ``(N, 3, S, S)`` float32 of instances ``rows`` of an
    :class:`~vnrrt.data.instances.Instances` file."""
    out = []
    for i in rows:
        inst = instances[int(i)]
        out.append(render_instance(inst.grid, inst.start_cell, inst.goal_cell, **render))
    size = instances.size
    return np.stack(out) if out else np.zeros((0, 3, size, size), np.float32)


@torch.inference_mode()
def predict(
    net: torch.nn.Module, images: np.ndarray, batch_size: int, device: torch.device
) -> tuple[np.ndarray, float]:
    """Probabilities ``(N, S, S)`` float16 of ``images`` ``(N, 3, S, S)`` and the network's
    seconds per map (bf16 autocast on CUDA)."""
    net = net.to(device).eval()
    autocast = torch.autocast("cuda", torch.bfloat16) if device.type == "cuda" else None
    out, seconds = [], 0.0
    for start in range(0, len(images), batch_size):
        x = torch.from_numpy(images[start : start + batch_size]).to(device)
        tick = time.perf_counter()
        with autocast or contextlib.nullcontext():
            probs = net(x).float().softmax(dim=1)[:, 1]  # (B, S, S)
        probs = probs.cpu()
        seconds += time.perf_counter() - tick
        out.append(probs.numpy().astype(np.float16))
    size = images.shape[-1]
    maps = np.concatenate(out) if out else np.zeros((0, size, size), np.float16)
    return maps, seconds / max(len(images), 1)


@dataclass(frozen=True)
class MetricSettings:
    """How heatmaps are measured (``predict.metric_*``, ``planner.taus``/``planner.tau``):
    "near" within ``radius`` px, recall at probability ``tau``, AP against targets dilated by
    ``ap_radius`` px with start/goal disks of ``endpoint_radius`` px left out, and the
    interior mass after M-VNRRT*'s mask at each of ``taus``."""

    radius: float
    tau: float
    ap_radius: float
    endpoint_radius: float
    taus: tuple[float, ...] = ()


def heatmap_metrics(maps: np.ndarray, instances, rows, ms: MetricSettings) -> dict[str, float]:
    """Heatmap metrics (:func:`vnrrt.model.metrics.heatmap_metric_set` with the settings
    ``ms``) of ``maps`` ``(N, S, S)`` against the A* paths and vertices of instances
    ``rows``."""
    from vnrrt.model.metrics import metric_collection  # torchmetrics: seconds to import

    metrics = metric_collection(
        ms.radius, ms.tau, ms.ap_radius, ms.endpoint_radius, ms.taus, with_target=False
    )
    shape = (instances.size, instances.size)
    for k, i in enumerate(rows):
        inst = instances[int(i)]
        masks = label_masks(inst.path, inst.vertices, shape)
        metrics.update(
            preds=torch.from_numpy(maps[k : k + 1].astype(np.float32)),
            **{k: torch.from_numpy(v)[None] for k, v in masks.items()},
        )
    return {k: float(v) for k, v in metrics.compute().items()}
