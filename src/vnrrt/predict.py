"""Predict heatmaps of the trained networks for the evaluation instances.

For each network of ``predict.networks`` (checkpoint ``<paths.models>/<name>.ckpt``): the
positive-class probability maps of the five named maps and of ``predict.test_instances``
evaluation instances of the test split (:func:`vnrrt.data.datamodule.evaluation_keys`), written
as float16 to ``<paths.heatmaps>/<name>.npz`` (format: :mod:`vnrrt.data.heatmaps`). The input
is rendered as in training (the checkpoint's record). Also measured on the test instances: the
heatmap metrics of :mod:`vnrrt.model.metrics` (mass near the vertices and the path against a
uniform map, vertex recall) and the inference time per map.
"""

from __future__ import annotations

import contextlib
import hashlib
import logging
import time
from pathlib import Path

import numpy as np
import torch
from omegaconf import DictConfig

from vnrrt.data.datamodule import InstanceDataset, evaluation_keys, verified_files
from vnrrt.data.heatmaps import write_heatmaps
from vnrrt.data.reader import Shard
from vnrrt.model.checkpoint import load_network
from vnrrt.model.metrics import metric_collection

log = logging.getLogger(__name__)


def pick_device(device: str) -> torch.device:
    """``"auto"``: CUDA when available, else CPU; otherwise ``torch.device(device)``."""
    if device == "auto":
        return torch.device("cuda" if torch.cuda.is_available() else "cpu")
    return torch.device(device)


@torch.inference_mode()
def predict_dataset(net: torch.nn.Module, data: InstanceDataset, batch_size: int,
                    device: torch.device, radius: float = 3.0,
                    tau: float = 0.5) -> tuple[np.ndarray, dict[str, float], float]:  # fmt: skip
    """Probabilities ``(N, S, S)`` float16 of ``data``'s instances, their heatmap metrics
    (within ``radius`` px, recall at ``tau``) and the inference seconds per map (network only,
    bf16 autocast on CUDA)."""
    net = net.to(device)
    metrics = metric_collection(radius, tau, with_target=False)
    autocast = torch.autocast("cuda", torch.bfloat16) if device.type == "cuda" else None
    out, seconds = [], 0.0
    for start in range(0, len(data), batch_size):
        items = [data[i] for i in range(start, min(start + batch_size, len(data)))]
        batch = {k: torch.stack([it[k] for it in items]) for k in items[0]}
        image = batch["image"].to(device)
        tick = time.perf_counter()
        with autocast or contextlib.nullcontext():
            probs = net(image).float().softmax(dim=1)[:, 1]  # (B, S, S)
        probs = probs.cpu()
        seconds += time.perf_counter() - tick
        metrics.update(preds=probs, vertices=batch["vertices"], path=batch["path"])
        out.append(probs.numpy().astype(np.float16))
    values = {k: float(v) for k, v in metrics.compute().items()}
    return np.concatenate(out), values, seconds / max(len(data), 1)


def _dataset(files, shard_ids, keys, record: dict) -> InstanceDataset:
    """Items rendered as the checkpoint's network was trained on."""
    target = record["target"]
    return InstanceDataset(files, shard_ids, keys, target["kind"], target["radius"],
                           **record["render"])  # fmt: skip


def _sha256(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def predict(cfg: DictConfig) -> dict:
    """Write the heatmaps of every ``predict.networks`` entry; return their metrics."""
    p = cfg.predict
    files = verified_files(cfg.paths.shards, cfg.paths.manifest, list(cfg.scale.shards))
    positions = evaluation_keys([Shard(f) for f in files], int(p.test_instances))
    shard_ids = list(cfg.scale.shards)
    named = Shard(cfg.paths.named_maps)
    named_keys = np.stack([np.zeros(named.n_instances, np.int64), named.instances()], axis=1)
    device, results = pick_device(p.device), {}
    for name in p.networks:
        ckpt = Path(cfg.paths.models) / f"{name}.ckpt"
        net, record = load_network(ckpt, name)
        test_maps, test_metrics, sec = predict_dataset(
            net, _dataset(files, shard_ids, positions, record), int(p.batch_size), device
        )
        named_data = _dataset([named.file], [-1], named_keys, record)
        named_maps, named_metrics, _ = predict_dataset(net, named_data, int(p.batch_size), device)
        test_keys = np.stack([np.asarray(shard_ids)[positions[:, 0]], positions[:, 1]], axis=1)
        write_heatmaps(Path(cfg.paths.heatmaps) / f"{name}.npz", named_maps, test_maps,
                       test_keys, network=name, target=record["target"],
                       checkpoint=str(ckpt), checkpoint_sha256=_sha256(ckpt))  # fmt: skip
        results[name] = {**{f"test/{k}": v for k, v in test_metrics.items()},
                         **{f"named/{k}": v for k, v in named_metrics.items()},
                         "test_instances": len(test_maps), "ms_per_map": 1e3 * sec}  # fmt: skip
        log.info("%s: %s", name, results[name])
    return results
