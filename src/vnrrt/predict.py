"""Predict heatmaps of the trained networks for the evaluation instances.

The networks are ``predict.networks`` (checkpoint ``<paths.models>/<name>.ckpt``); the input
is rendered as in training (the checkpoint's record). The work is split so that it can run
as shard jobs (:mod:`vnrrt.multirun`) as well as DVC stages, writing the same files
(format: :mod:`vnrrt.data.heatmaps`):

* :func:`predict_part` (stage ``predict@<k>``): part ``k`` of ``predict.parts`` of the
  ``predict.test_instances`` evaluation instances of the test split
  (:func:`vnrrt.data.datamodule.evaluation_keys`) -> ``<paths.heatmaps>/part_<k>.npz``.
* :func:`predict_named` (stage ``predict_named``): the five named maps ->
  ``<paths.named_heatmaps>``, and the heatmap metrics of :mod:`vnrrt.model.metrics`
  (mass near the vertices and the path against a uniform map, vertex recall) over the named
  maps and over all parts' stored heatmaps, with the inference time per map.
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

from vnrrt.config import ConfigError, check_parts
from vnrrt.data.datamodule import InstanceDataset, evaluation_keys, verified_files
from vnrrt.data.heatmaps import part_file, part_rows, read_parts, write_heatmaps
from vnrrt.data.reader import Shard
from vnrrt.model.checkpoint import load_network
from vnrrt.model.metrics import metric_collection

log = logging.getLogger(__name__)


def pick_device(device: str) -> torch.device:
    """``"auto"``: CUDA when available, else CPU; otherwise ``torch.device(device)``."""
    if device == "auto":
        return torch.device("cuda" if torch.cuda.is_available() else "cpu")
    return torch.device(device)


def _batches(data: InstanceDataset, batch_size: int):
    """Stacked item dicts of ``data`` in order, ``batch_size`` items at a time."""
    for start in range(0, len(data), batch_size):
        items = [data[i] for i in range(start, min(start + batch_size, len(data)))]
        yield {k: torch.stack([it[k] for it in items]) for k in items[0]}


@torch.inference_mode()
def predict_dataset(net: torch.nn.Module, data: InstanceDataset, batch_size: int,
                    device: torch.device) -> tuple[np.ndarray, float]:  # fmt: skip
    """Probabilities ``(N, S, S)`` float16 of ``data``'s instances and the inference seconds
    per map (network only, bf16 autocast on CUDA)."""
    net = net.to(device).eval()
    autocast = torch.autocast("cuda", torch.bfloat16) if device.type == "cuda" else None
    out, seconds = [], 0.0
    for batch in _batches(data, batch_size):
        image = batch["image"].to(device)
        tick = time.perf_counter()
        with autocast or contextlib.nullcontext():
            probs = net(image).float().softmax(dim=1)[:, 1]  # (B, S, S)
        probs = probs.cpu()
        seconds += time.perf_counter() - tick
        out.append(probs.numpy().astype(np.float16))
    size = data[0]["image"].shape[-1] if len(data) else 0
    maps = np.concatenate(out) if out else np.zeros((0, size, size), np.float16)
    return maps, seconds / max(len(data), 1)


def heatmap_metrics(maps: np.ndarray, data: InstanceDataset, batch_size: int = 64,
                    radius: float = 3.0, tau: float = 0.5) -> dict[str, float]:  # fmt: skip
    """Heatmap metrics (:func:`vnrrt.model.metrics.heatmap_metrics`, within ``radius`` px,
    recall at ``tau``) of ``maps`` ``(N, S, S)`` against ``data``'s A* paths and vertices."""
    metrics = metric_collection(radius, tau, with_target=False)
    row = 0
    for batch in _batches(data, batch_size):
        n = len(batch["path"])
        preds = torch.from_numpy(maps[row : row + n].astype(np.float32))
        metrics.update(preds=preds, vertices=batch["vertices"], path=batch["path"])
        row += n
    return {k: float(v) for k, v in metrics.compute().items()}


def _dataset(files, shard_ids, keys, record: dict) -> InstanceDataset:
    """Items rendered as the checkpoint's network was trained on."""
    target = record["target"]
    return InstanceDataset(files, shard_ids, keys, target["kind"], target["radius"],
                           **record["render"])  # fmt: skip


def _networks(cfg: DictConfig) -> dict[str, tuple[torch.nn.Module, dict, dict]]:
    """``{name: (network, checkpoint record, file info)}`` of every ``predict.networks``."""
    out = {}
    for name in cfg.predict.networks:
        ckpt = Path(cfg.paths.models) / f"{name}.ckpt"
        net, record = load_network(ckpt, name)
        sha = hashlib.sha256(ckpt.read_bytes()).hexdigest()
        info = {"target": record["target"], "checkpoint": str(ckpt), "checkpoint_sha256": sha}
        out[name] = (net, record, info)
    return out


def _evaluation_positions(
    cfg: DictConfig,
) -> tuple[list[Path], list[int], np.ndarray, np.ndarray]:
    """Verified shard files, their ids, the evaluation instances ``(R, 2)`` as (file
    position, instance index) and as the keys of the heatmap files (shard id, instance)."""
    shard_ids = [int(s) for s in cfg.scale.shards]
    files = verified_files(cfg.paths.shards, cfg.paths.manifest, shard_ids)
    positions = evaluation_keys([Shard(f) for f in files], int(cfg.predict.test_instances))
    keys = np.stack([np.asarray(shard_ids)[positions[:, 0]], positions[:, 1]], axis=1)
    return files, shard_ids, positions, keys


def predict_part(cfg: DictConfig, part: int) -> dict:
    """Heatmaps of every network for evaluation part ``part`` -> ``part_<part>.npz``; returns
    ``{network: {"instances", "ms_per_map"}}``."""
    parts = check_parts(cfg.predict.parts, "predict.parts")
    if part not in parts:
        raise ConfigError(f"part {part} is not in predict.parts {parts}")
    files, shard_ids, positions, keys = _evaluation_positions(cfg)
    rows = part_rows(len(positions), part, len(parts))
    positions, keys = positions[rows], keys[rows]
    device, maps, meta = pick_device(cfg.predict.device), {}, {}
    for name, (net, record, info) in _networks(cfg).items():
        data = _dataset(files, shard_ids, positions, record)
        maps[name], sec = predict_dataset(net, data, int(cfg.predict.batch_size), device)
        meta[name] = {**info, "ms_per_map": 1e3 * sec, "device": device.type}
    write_heatmaps(part_file(cfg.paths.heatmaps, part), keys, maps, networks=meta,
                   part=part, parts=len(parts))  # fmt: skip
    log.info("part %d/%d: %d instances x %d networks", part, len(parts), len(keys), len(maps))
    return {n: {"instances": len(keys), "ms_per_map": m["ms_per_map"]} for n, m in meta.items()}


def predict_named(cfg: DictConfig) -> dict:
    """Heatmaps of every network for the named maps -> ``paths.named_heatmaps``; returns the metrics
    ``{network: {"named/<metric>", "test/<metric>", "test_instances", "ms_per_map"}}``, the
    ``test/`` ones over the stored heatmaps of every part (so independent of the split)."""
    named = Shard(cfg.paths.named_maps)
    named_keys = np.stack([np.zeros(named.n_instances, np.int64), named.instances()], axis=1)
    files, shard_ids, positions, keys = _evaluation_positions(cfg)
    parts = read_parts(cfg.paths.heatmaps, check_parts(cfg.predict.parts, "predict.parts"))
    if not np.array_equal(parts["keys"], keys):
        raise ConfigError(f"heatmap parts in {cfg.paths.heatmaps} are not the evaluation "
                          f"instances of this config (re-run `dvc repro predict`)")  # fmt: skip
    device, maps, meta, results = pick_device(cfg.predict.device), {}, {}, {}
    for name, (net, record, info) in _networks(cfg).items():
        named_data = _dataset([named.file], [-1], named_keys, record)
        maps[name], _ = predict_dataset(net, named_data, int(cfg.predict.batch_size), device)
        meta[name] = info
        named_metrics = heatmap_metrics(maps[name], named_data)
        test = heatmap_metrics(parts["maps"][name], _dataset(files, shard_ids, positions, record))
        ms_parts = [m["networks"][name]["ms_per_map"] for m in parts["meta"]]
        ms = float(np.average(ms_parts, weights=parts["counts"])) if len(positions) else 0.0
        results[name] = {**{f"test/{k}": v for k, v in test.items()},
                         **{f"named/{k}": v for k, v in named_metrics.items()},
                         "test_instances": len(positions), "ms_per_map": ms}  # fmt: skip
        log.info("%s: %s", name, results[name])
    named_file_keys = np.stack([np.full(named.n_instances, -1), named.instances()], axis=1)
    write_heatmaps(cfg.paths.named_heatmaps, named_file_keys, maps, networks=meta)
    return results
