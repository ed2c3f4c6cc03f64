"""Entry points of the prediction stages.

* ``predict@<k>``: heatmaps of every network of ``predict.networks`` for part ``k`` of the
  instances file -> ``paths.heatmaps_part(k)`` (bytes depend only on the inputs and
  ``predict.threads``; the inference time goes to ``paths.timing_part(k)``);
* ``predict_metrics``: the heatmap metrics over the named maps and the random instances with
  their settings, the inference time per map (``paths.predict_metrics``) and Fig. 3
  (``paths.heatmaps_figure``); the MLflow run ``predict <scale>`` (:mod:`vnrrt.predict.runs`).

The budget curve's ``budget_predict@<steps>`` (:mod:`.training_budget`) runs both for one
training budget.
"""

from __future__ import annotations

import logging
from pathlib import Path

import numpy as np
import torch
from omegaconf import DictConfig

from vnrrt.config import ConfigError, check_parts, section
from vnrrt.config.paths import Paths

log = logging.getLogger(__name__)


def pick_device(device: str) -> torch.device:
    """``"auto"``: CUDA when available, else CPU; otherwise ``torch.device(device)``."""
    if device == "auto":
        return torch.device("cuda" if torch.cuda.is_available() else "cpu")
    return torch.device(device)


def _networks(checkpoints: dict[str, Path]) -> dict:
    """``{name: (network, record, checkpoint sha256)}`` of each network's checkpoint of
    ``checkpoints`` (name -> file, its ``.sha256`` sidecar required)."""
    from vnrrt.infra.io import sha256
    from vnrrt.model.checkpoint import load_network

    out = {}
    for name, ckpt in checkpoints.items():
        net, record = load_network(ckpt, name, verify=True)
        out[name] = (net, record, sha256(ckpt))
    return out


def predict_rows(cfg: DictConfig, checkpoints: dict[str, Path], instances, rows) -> tuple:
    """``(maps, meta, timing)`` of the networks of ``checkpoints`` on instances ``rows``:
    ``{network: (len(rows), S, S) float16}``, what the heatmap file records of each, and its
    inference time (``predict.batch_size``, ``predict.device``)."""
    from vnrrt.predict.batch import inputs, predict

    device, maps, meta, timing = pick_device(str(cfg.predict.device)), {}, {}, {}
    for name, (net, record, sha) in _networks(checkpoints).items():
        images = inputs(instances, rows, record["render"])
        maps[name], sec = predict(net, images, int(cfg.predict.batch_size), device)
        meta[name] = {"target": record["target"], "checkpoint_sha256": sha}
        timing[name] = {"ms_per_map": 1e3 * sec, "device": device.type, "maps": len(rows)}
    return maps, meta, timing


def run_predict_part(cfg: DictConfig, part: int) -> dict:
    """Stage ``predict@<part>`` (module doc); returns ``{network: ms per map}``."""
    from vnrrt.data.heatmaps import part_rows, write_heatmaps
    from vnrrt.data.instances import Instances
    from vnrrt.infra.io import write_json

    paths = section(cfg, "paths", Paths)
    parts = check_parts(cfg.predict.parts, "predict.parts")
    if part not in parts:
        raise ConfigError(f"part {part} is not in predict.parts {parts}")
    torch.set_num_threads(int(cfg.predict.threads))
    instances = Instances(paths.instances)
    rows = np.arange(len(instances))[part_rows(len(instances), part, len(parts))]
    checkpoints = {name: paths.checkpoint(name) for name in cfg.predict.networks}
    maps, meta, timing = predict_rows(cfg, checkpoints, instances, rows)
    write_heatmaps(paths.heatmaps_part(part), instances.keys[rows], maps, networks=meta,
                   part=part, parts=len(parts))  # fmt: skip
    write_json(paths.timing_part(part), timing)
    log.info("part %d/%d: %d instances x %d networks", part, len(parts), len(rows), len(maps))
    return {n: t["ms_per_map"] for n, t in timing.items()}


def metric_settings(cfg: DictConfig):
    """The heatmap metrics' settings: ``predict.metric_*`` and the M-VNRRT* thresholds."""
    from vnrrt.names import mask_taus
    from vnrrt.predict.batch import MetricSettings

    p = cfg.predict
    return MetricSettings(
        float(p.metric_radius),
        float(p.metric_tau),
        float(p.metric_ap_radius),
        float(p.metric_endpoint_radius),
        tuple(mask_taus(list(cfg.planner.taus), float(cfg.planner.tau))),
    )


def split_metrics(maps: np.ndarray, instances, ms) -> dict[str, float]:
    """The heatmap metrics (settings ``ms``) of ``maps`` ``(N, S, S)`` (one per instance of
    the file, in order): ``test/<metric>`` over the random instances, ``named/<metric>`` over
    the named maps."""
    from vnrrt.predict.batch import heatmap_metrics

    kinds = np.array(instances.kinds)
    out = {}
    for prefix, kind in (("test", "random"), ("named", "named")):
        rows = np.flatnonzero(kinds == kind)
        metrics = heatmap_metrics(maps[rows], instances, rows, ms)
        out |= {f"{prefix}/{k}": v for k, v in metrics.items()}
    return out


def network_metrics(maps: dict, instances, ms, targets: dict, timing: list[dict]) -> dict:
    """``{network: metrics}`` of the heatmaps ``maps`` (``{network: (N, S, S)}``) of the
    whole instances file: :func:`split_metrics`, the number of random instances, the
    network's target kind (``targets``) and its inference time, averaged over the ``timing``
    of the prediction parts."""
    results = {}
    n_random = int(np.sum(np.array(instances.kinds) == "random"))
    for name, heat in maps.items():
        counts = [t[name]["maps"] for t in timing]
        ms_per_map = np.average([t[name]["ms_per_map"] for t in timing], weights=counts)
        results[name] = {**split_metrics(heat, instances, ms), "test_instances": n_random,
                         "target": targets[name], "ms_per_map": float(ms_per_map),
                         "device": timing[0][name]["device"]}  # fmt: skip
        log.info("%s: %s", name, results[name])
    return results


def run_predict_metrics(cfg: DictConfig) -> dict:
    """Stage ``predict_metrics`` (module doc); returns what it wrote: ``{"settings": the
    metrics' settings, "networks": {network: metrics, target, inference time}}``."""
    import dataclasses

    from vnrrt.data.heatmaps import read_parts
    from vnrrt.data.instances import Instances
    from vnrrt.infra.io import read_json, write_json
    from vnrrt.tracking.experiments import LoggerConfig
    from vnrrt.tracking.store import check_store, tracking_uri
    from vnrrt.viz.evaluation import save_heatmaps

    paths = section(cfg, "paths", Paths)
    logger = section(cfg, "logger", LoggerConfig)
    if logger.enabled:  # an unreachable store fails here, before any work
        check_store(tracking_uri(logger.uri))
    parts = check_parts(cfg.predict.parts, "predict.parts")
    instances = Instances(paths.instances)
    files = read_parts(paths.heatmaps, parts)
    if not np.array_equal(files["keys"], instances.keys):
        raise ConfigError(
            f"heatmap parts in {paths.heatmaps} do not cover the instances of "
            f"{paths.instances} (re-run `dvc repro`)"
        )
    timing = [read_json(paths.timing_part(k)) for k in parts]
    targets = {n: m["target"]["kind"] for n, m in files["meta"][0]["networks"].items()}
    ms = metric_settings(cfg)
    results = network_metrics(files["maps"], instances, ms, targets, timing)
    out = {"settings": dataclasses.asdict(ms), "networks": results}
    write_json(paths.predict_metrics, out)
    named = np.flatnonzero(np.array(instances.kinds) == "named")
    shown = [instances[int(i)] for i in named]
    save_heatmaps(
        paths.heatmaps_figure,
        [i.grid for i in shown],
        [i.path for i in shown],
        [i.vertices for i in shown],
        [i.start_cell for i in shown],
        [i.goal_cell for i in shown],
        {n: m[named] for n, m in files["maps"].items()},
        titles=[f"Map {k + 1}: {i.map.replace('_', ' ')}" for k, i in enumerate(shown)],
    )
    if logger.enabled:
        from vnrrt.predict.runs import log_predict

        files = {"predict.json": paths.predict_metrics, "figure": paths.heatmaps_figure,
                 "instances": paths.instances}  # fmt: skip
        trainings = {n: paths.train_metrics(n) for n in results}
        log_predict(logger, str(cfg.scale.name), out, files, trainings, shown)
    return out
