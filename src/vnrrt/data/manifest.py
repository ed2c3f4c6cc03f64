"""The dataset manifest: per-shard counts and sha256 checksums, plus summary metrics.

``manifest.json`` lets consumers check that the shards they read are the ones the
pipeline wrote (:func:`verify_manifest`); ``data.json`` holds the figures DVC reports with
``dvc metrics show`` (instances, bytes per instance, path and vertex statistics).
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from vnrrt.data.reader import TEST, TRAIN, Shard
from vnrrt.data.shards import FORMAT_VERSION, ShardError, shard_file
from vnrrt.infra.io import read_json, sha256, write_json


def shard_entry(path: Path) -> dict:
    """Counts and checksum of one shard file (validated by loading it)."""
    shard = Shard(path)
    a = shard.arrays
    inst_split = a["split"][a["inst_map"]]
    return {
        "file": path.name,
        "sha256": sha256(path),
        "bytes": path.stat().st_size,
        "maps": shard.n_maps,
        "instances": shard.n_instances,
        "train_maps": int(np.sum(a["split"] == TRAIN)),
        "test_maps": int(np.sum(a["split"] == TEST)),
        "train_instances": int(np.sum(inst_split == TRAIN)),
        "test_instances": int(np.sum(inst_split == TEST)),
        "path_cells": int(len(a["path_moves"]) + shard.n_instances),
        "vertices": int(len(a["vertex_steps"])),
        "optimal_length_sum": float(a["inst_length"].sum()),
    }


def summarize(entries: list[dict]) -> dict:
    """Totals and per-instance means over shard entries (the DVC metrics)."""
    tot = {k: sum(e[k] for e in entries) for k in entries[0] if k not in ("file", "sha256")}
    n = max(tot["instances"], 1)
    return {
        "shards": len(entries),
        "maps": tot["maps"],
        "instances": tot["instances"],
        "train_instances": tot["train_instances"],
        "test_instances": tot["test_instances"],
        "bytes": tot["bytes"],
        "bytes_per_instance": tot["bytes"] / n,
        "mean_path_cells": tot["path_cells"] / n,
        "mean_vertices": tot["vertices"] / n,
        "mean_optimal_length": tot["optimal_length_sum"] / n,
    }


def build_manifest(shards_dir: str | Path, shard_ids: list[int], out: str | Path) -> dict:
    """Write ``out`` (manifest JSON) for shards ``shard_ids``; return the summary metrics."""
    entries = [shard_entry(shard_file(shards_dir, i)) for i in shard_ids]
    for entry, i in zip(entries, shard_ids):  # paths relative to the manifest's folder
        entry["file"] = os.path.relpath(shard_file(shards_dir, i), Path(out).parent)
    summary = summarize(entries)
    write_json(out, {"format_version": FORMAT_VERSION, "shards": entries, "summary": summary})
    return summary


def verify_manifest(manifest: str | Path) -> list[Path]:
    """Check every shard listed in ``manifest`` against its checksum; return their paths.

    Raises :class:`ShardError` naming the first missing or modified shard.
    """
    manifest = Path(manifest)
    if not manifest.is_file():
        raise ShardError(f"manifest {manifest} does not exist (run `dvc repro`)")
    try:
        doc = read_json(manifest)
        entries = [(e["file"], e["sha256"]) for e in doc["shards"]]
    except (ValueError, KeyError, TypeError) as err:  # not JSON, or entries without fields
        why = f"no field {err}" if isinstance(err, KeyError) else str(err).splitlines()[0]
        raise ShardError(f"manifest {manifest} is not a shard manifest: {why}") from None
    paths = []
    for file, digest in entries:
        path = manifest.parent / file
        if not path.is_file():
            raise ShardError(f"shard {path} listed in {manifest} is missing")
        if sha256(path) != digest:
            raise ShardError(f"shard {path} does not match its checksum in {manifest}")
        paths.append(path)
    return paths


def verified_files(shards_dir, manifest, shard_ids: list[int]) -> list[Path]:
    """Shard files of ``shard_ids``, each checked against its checksum in ``manifest``.

    Raises :class:`ShardError` naming a shard that is modified, missing or not in the manifest.
    """
    listed = {p.resolve() for p in verify_manifest(manifest)}
    files = [shard_file(shards_dir, s) for s in shard_ids]
    for f in files:
        if f.resolve() not in listed:
            raise ShardError(f"shard {f} is not listed in manifest {manifest} (run `dvc repro`)")
    return files
