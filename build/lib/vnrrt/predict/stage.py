"""Entry points of the prediction stages.

* ``predict@<k>``: heatmaps of every network of ``predict.networks`` for part ``k`` of the
  instances file -> ``<paths.heatmaps>/part_<k>.npz`` (bytes depend only on the inputs and
  ``predict.threads``; the inference time goes to ``<paths.timing>/predict_<k>.json``);
* ``predict_metrics``: the heatmap metrics over the named maps and the random instances,
  the inference time per map (``<paths.metrics>/predict.json``) and Fig. 3.
"""

from __future__ import annotations

import logging
from pathlib import Path

import numpy as np
import torch
from omegaconf import DictConfig

from vnrrt.config import ConfigError, check_parts

log = logging.getLogger(__name__)


def pick_device(device: str) -> torch.device:
    """``"auto"``: CUDA when available, else CPU; otherwise ``torch.device(device)``."""
    if device == "auto":
        return torch.device("cuda" if torch.cuda.is_available() else "cpu")
    return torch.device(device)


def _networks(cfg: DictConfig) -> dict:
    """``{name: (network, record, checkpoint sha256)}`` of every ``predict.networks``."""
    from vnrrt.io import sha256
    from vnrrt.model.checkpoint import load_network

    out = {}
    for name in cfg.predict.networks:
        ckpt = Path(cfg.paths.models) / f"{name}.ckpt"
        net, record = load_network(ckpt, name, verify=True)
        out[name] = (net, record, sha256(ckpt))
    return out


def run_predict_part(cfg: DictConfig, part: int) -> dict:
    """Stage ``predict@<part>`` (module doc); returns ``{network: ms per map}``."""
    from vnrrt.data.heatmaps import part_file, part_rows, write_heatmaps
    from vnrrt.evaluation.instances import Instances
    from vnrrt.io import write_json
    from vnrrt.predict.batch import inputs, predict

    parts = check_parts(cfg.predict.parts, "predict.parts")
    if part not in parts:
        raise ConfigError(f"part {part} is not in predict.parts {parts}")
    torch.set_num_threads(int(cfg.predict.threads))
    instances = Instances(cfg.paths.instances)
    rows = np.arange(len(instances))[part_rows(len(instances), part, len(parts))]
    device, maps, meta, timing = pick_device(cfg.predict.device), {}, {}, {}
    for name, (net, record, sha) in _networks(cfg).items():
        images = inputs(instances, rows, record["render"])
        maps[name], sec = predict(net, images, int(cfg.predict.batch_size), device)
        meta[name] = {"target": record["target"], "checkpoint_sha256": sha}
        timing[name] = {"ms_per_map": 1e3 * sec, "device": device.type, "maps": len(rows)}
    write_heatmaps(
        part_file(cfg.paths.heatmaps, part),
        instances.keys[rows],
        maps,
        networks=meta,
        part=part,
        parts=len(parts),
    )
    write_json(Path(cfg.paths.timing) / f"predict_{part}.json", timing)
    log.info("part %d/%d: %d instances x %d networks", part, len(parts), len(rows), len(maps))
    return {n: t["ms_per_map"] for n, t in timing.items()}


def run_predict_metrics(cfg: DictConfig) -> dict:
    """Stage ``predict_metrics`` (module doc); returns the metrics written."""
    from vnrrt.data.heatmaps import read_parts
    from vnrrt.evaluation.instances import Instances
    from vnrrt.io import read_json, write_json
    from vnrrt.predict.batch import heatmap_metrics
    from vnrrt.viz.evaluation import save_heatmaps

    parts = check_parts(cfg.predict.parts, "predict.parts")
    instances = Instances(cfg.paths.instances)
    files = read_parts(cfg.paths.heatmaps, parts)
    if not np.array_equal(files["keys"], instances.keys):
        raise ConfigError(
            f"heatmap parts in {cfg.paths.heatmaps} do not cover the instances of "
            f"{cfg.paths.instances} (re-run `dvc repro`)"
        )
    kinds = np.array(instances.kinds)
    named, random = np.flatnonzero(kinds == "named"), np.flatnonzero(kinds == "random")
    timing = [read_json(Path(cfg.paths.timing) / f"predict_{k}.json") for k in parts]
    radius = float(cfg.predict.metric_radius)
    results = {}
    for name, maps in files["maps"].items():
        counts = [t[name]["maps"] for t in timing]
        ms = float(np.average([t[name]["ms_per_map"] for t in timing], weights=counts))
        results[name] = {
            **{
                f"test/{k}": v
                for k, v in heatmap_metrics(maps[random], instances, random, radius).items()
            },
            **{
                f"named/{k}": v
                for k, v in heatmap_metrics(maps[named], instances, named, radius).items()
            },
            "test_instances": len(random),
            "ms_per_map": ms,
            "device": timing[0][name]["device"],
        }
        log.info("%s: %s", name, results[name])
    write_json(Path(cfg.paths.metrics) / "predict.json", results)
    shown = [instances[int(i)] for i in named]
    save_heatmaps(
        Path(cfg.paths.figures) / "heatmaps.png",
        [i.grid for i in shown],
        [i.path for i in shown],
        [i.vertices for i in shown],
        [i.start_cell for i in shown],
        [i.goal_cell for i in shown],
        {n: m[named] for n, m in files["maps"].items()},
        titles=[f"Map {k + 1}: {i.map.replace('_', ' ')}" for k, i in enumerate(shown)],
    )
    return results
