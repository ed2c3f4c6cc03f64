"""Predicted heatmaps on disk (written by the ``predict@<part>`` and ``predict_named`` stages,
read by evaluation).

One ``.npz`` per group of instances, format version 2, every network of ``predict.networks``
in it: ``<paths.named_heatmaps>`` (the five named maps) and ``<paths.heatmaps>/part_<k>.npz``
(part ``k`` of the ``R`` evaluation instances of the test split, :func:`part_rows`). ``S`` is
the map size; a heatmap is the network's probability of
the positive class (vertex for VertexNet, path cell for the NRRT* network), indexed
``heatmap[y, x]`` like grids:

==================  ==================  ==================================================
field               shape, dtype        meaning
==================  ==================  ==================================================
``format_version``  (), int64           :data:`FORMAT_VERSION`
``meta``            (), str             JSON: per network its target, checkpoint, sha256
                                        and inference ms per map; the part
``keys``            (N, 2) int64        (shard id, instance index); named maps: (-1, i)
``net_<network>``   (N, S, S) float16   that network's heatmaps, in ``keys`` order
==================  ==================  ==================================================

The evaluation instances are :func:`vnrrt.data.splits.evaluation_keys`: ``R`` evenly
spaced instances of the test split (test maps of the shards, in shard order).
"""

from __future__ import annotations

import io
import json
from pathlib import Path

import numpy as np

from vnrrt.config.paths import heatmaps_part_file as part_file
from vnrrt.infra.io import atomic_write_bytes, load_npz

FORMAT_VERSION = 2
PREFIX = "net_"  # field name prefix of a network's heatmaps


class HeatmapError(ValueError):
    """A heatmap file is missing or malformed; the message names the file."""


def part_rows(n: int, part: int, parts: int) -> slice:
    """Rows of part ``part`` (0-based) of ``parts`` contiguous, near-equal parts of ``n``."""
    if not 0 <= part < parts:
        raise ValueError(f"part {part} is not in 0..{parts - 1}")
    return slice(part * n // parts, (part + 1) * n // parts)


def write_heatmaps(path: str | Path, keys: np.ndarray, maps: dict[str, np.ndarray],
                   **meta) -> None:  # fmt: skip
    """Write ``maps`` ``{network: (N, S, S)}`` (stored float16) for ``keys`` ``(N, 2)``
    atomically; ``meta`` goes to JSON."""
    keys = np.asarray(keys, np.int64).reshape(-1, 2)
    arrays = {
        "format_version": np.array(FORMAT_VERSION, np.int64),
        "meta": np.array(json.dumps(meta, sort_keys=True)),
        "keys": keys,
    }
    for name, heat in maps.items():
        if len(heat) != len(keys):
            raise ValueError(f"{len(heat)} heatmaps of {name!r} for {len(keys)} keys")
        arrays[PREFIX + name] = np.asarray(heat, np.float16)
    buf = io.BytesIO()
    np.savez_compressed(buf, **arrays)
    atomic_write_bytes(Path(path), lambda f: f.write(buf.getvalue()))


def read_heatmaps(path: str | Path) -> dict:
    """``{"keys": (N, 2), "maps": {network: (N, S, S) float16}, "meta": dict}`` of a heatmap
    file; :class:`HeatmapError` naming the file if it is missing or malformed."""
    path = Path(path)
    if not path.is_file():
        raise HeatmapError(
            f"heatmap file {path} does not exist (run the predict stages: `dvc repro`)"
        )
    arrays = load_npz(path, "heatmap file", HeatmapError)  # cut, damaged, foreign
    missing = [k for k in ("format_version", "meta", "keys") if k not in arrays]
    if missing or int(arrays["format_version"]) != FORMAT_VERSION:
        raise HeatmapError(f"heatmap file {path}: missing {missing} or not format {FORMAT_VERSION}")
    maps = {k[len(PREFIX) :]: v for k, v in arrays.items() if k.startswith(PREFIX)}
    for name, heat in maps.items():
        if len(heat) != len(arrays["keys"]):
            raise HeatmapError(f"heatmap file {path}: {name} and keys differ in length")
    return {"keys": arrays["keys"], "maps": maps, "meta": json.loads(str(arrays["meta"]))}


def read_parts(directory: str | Path, parts: list[int]) -> dict:
    """The evaluation heatmaps of all ``parts`` concatenated in part order, as
    :func:`read_heatmaps` returns them (``meta``: the list of the parts' meta; ``counts``: their
    numbers of instances)."""
    files = [read_heatmaps(part_file(directory, k)) for k in parts]
    names = [sorted(f["maps"]) for f in files]
    if any(n != names[0] for n in names):
        raise HeatmapError(f"heatmap parts in {directory} hold different networks: {names}")
    return {
        "keys": np.concatenate([f["keys"] for f in files]),
        "maps": {n: np.concatenate([f["maps"][n] for f in files]) for n in names[0]},
        "meta": [f["meta"] for f in files],
        "counts": [len(f["keys"]) for f in files],
    }
