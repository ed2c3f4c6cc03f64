"""A trained network of a GPU run on the bundle's instances: heatmaps, inference
throughput, and the heatmap metrics of :func:`vnrrt.predict.batch.heatmap_metrics` (as the
``predict_metrics`` stage computes them for the CPU-trained networks)."""

from __future__ import annotations

import time

import numpy as np
import torch

from vnrrt.data.returned import Instances
from vnrrt.names import mask_taus
from vnrrt.pipeline.gpu.probe import infer_rate
from vnrrt.predict.batch import MetricSettings, heatmap_metrics, inputs, predict


def metric_settings(cfg: dict) -> MetricSettings:
    """The heatmap metrics' settings of the bundle's config (``predict.metric_*``, the
    M-VNRRT* thresholds), as the ``predict_metrics`` stage uses them."""
    p, planner = cfg["predict"], cfg["planner"]
    return MetricSettings(
        float(p["metric_radius"]),
        float(p["metric_tau"]),
        float(p["metric_ap_radius"]),
        float(p["metric_endpoint_radius"]),
        tuple(mask_taus(planner["taus"], planner["tau"])),
    )


def heldout_metrics(maps: np.ndarray, instances: Instances, ms: MetricSettings) -> dict:
    """:func:`vnrrt.predict.batch.heatmap_metrics` over the random instances (``test/``,
    the test split's, never trained on) and the named maps (``named/``)."""
    kinds, out = np.array(instances.kinds), {}
    for kind, prefix in (("random", "test"), ("named", "named")):
        rows = np.flatnonzero(kinds == kind)
        if len(rows):
            found = heatmap_metrics(maps[rows], instances, rows, ms)
            out.update({f"{prefix}/{k}": v for k, v in found.items()})
    return {**out, "test_instances": int(np.sum(kinds == "random"))}


def evaluate(module, instances: Instances, cfg: dict, device, batch: int) -> tuple:
    """Heatmaps ``(N, S, S)`` float16 of every instance, and the network's inference
    throughput, heldout metrics and the seconds of each part."""
    ticks = [time.perf_counter()]
    net = module.net.to(device).eval()
    images = inputs(instances, range(len(instances)), module.record["render"])
    maps, sec = predict(net, images, int(cfg["predict"]["batch_size"]), device)
    ticks.append(time.perf_counter())
    x = torch.from_numpy(images).repeat(-(-batch // len(images)), 1, 1, 1)[:batch]
    rate = infer_rate(net, x.to(device), cfg["trainer"]["precision"])
    ticks.append(time.perf_counter())
    heldout = heldout_metrics(maps, instances, metric_settings(cfg))
    ticks.append(time.perf_counter())
    seconds = dict(zip(("predict", "infer_probe", "metrics"), np.diff(ticks).tolist()))
    found = {"ms_per_map": 1e3 * sec, "infer_images_per_s": rate, "infer_batch": batch}
    return maps, {**found, "heldout": heldout, "seconds": seconds}
