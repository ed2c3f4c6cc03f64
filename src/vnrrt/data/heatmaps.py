"""Predicted heatmaps on disk (written by the ``predict`` stage, read by evaluation).

One ``.npz`` per network (``<paths.heatmaps>/<network>.npz``), format version 1. ``S`` is the
map size; heatmaps are the network's probability of the positive class (vertex for VertexNet,
path cell for the NRRT* network), indexed ``heatmap[y, x]`` like grids:

================  ==================  ==================================================
field             shape, dtype        meaning
================  ==================  ==================================================
``format_version`` (), int64          :data:`FORMAT_VERSION`
``meta``          (), str             JSON: network, target, checkpoint and its sha256
``named``         (5, S, S) float16   the named maps, in the instance order of
                                      ``paths.named_maps``
``test``          (R, S, S) float16   the evaluation instances of the test split
``test_keys``     (R, 2) int64        their (shard id, instance index)
================  ==================  ==================================================

The evaluation instances are :func:`vnrrt.data.datamodule.evaluation_keys`: ``R`` evenly
spaced instances of the test split (test maps of the shards, in shard order).
"""

from __future__ import annotations

import io
import json
from pathlib import Path

import numpy as np

from vnrrt.data.shards import atomic_write_bytes

FORMAT_VERSION = 1
FIELDS = ("format_version", "meta", "named", "test", "test_keys")


class HeatmapError(ValueError):
    """A heatmap file is missing or malformed; the message names the file."""


def write_heatmaps(path: str | Path, named: np.ndarray, test: np.ndarray,
                   test_keys: np.ndarray, **meta) -> None:  # fmt: skip
    """Write the heatmaps of one network (float16) atomically; ``meta`` goes to JSON."""
    arrays = {
        "format_version": np.array(FORMAT_VERSION, np.int64),
        "meta": np.array(json.dumps(meta, sort_keys=True)),
        "named": np.asarray(named, np.float16),
        "test": np.asarray(test, np.float16),
        "test_keys": np.asarray(test_keys, np.int64).reshape(-1, 2),
    }
    buf = io.BytesIO()
    np.savez_compressed(buf, **arrays)
    atomic_write_bytes(Path(path), lambda f: f.write(buf.getvalue()))


def read_heatmaps(path: str | Path) -> dict:
    """All fields of a heatmap file (``meta`` parsed); :class:`HeatmapError` if malformed."""
    path = Path(path)
    if not path.is_file():
        raise HeatmapError(f"heatmap file {path} does not exist (run `dvc repro predict`)")
    with np.load(path, allow_pickle=False) as npz:
        arrays = {k: npz[k] for k in npz.files}
    missing = [k for k in FIELDS if k not in arrays]
    if missing or int(arrays["format_version"]) != FORMAT_VERSION:
        raise HeatmapError(f"heatmap file {path}: missing {missing} or not format {FORMAT_VERSION}")
    if len(arrays["test"]) != len(arrays["test_keys"]):
        raise HeatmapError(f"heatmap file {path}: test and test_keys differ in length")
    arrays["meta"] = json.loads(str(arrays["meta"]))
    return arrays
