"""What a GPU run returns, the machine's limits on it, and the one reader of it.

The output folder (``$OUT`` on the machine) holds, at most :data:`MAX_FILES` files of at most
:data:`MAX_FILE_BYTES` each and :data:`MAX_TOTAL_BYTES` together, no deeper than
:data:`MAX_DEPTH` folders, named in letters, digits, ``.``, ``_`` and ``-``:

====================  ============================================================
file                  content
====================  ============================================================
``heatmaps/part_<k>`` heatmaps of every instance of the instances file, format of
``.npz``              :mod:`vnrrt.data.heatmaps` (float16, compressed), networks
                      :data:`NETWORKS`; meta: the run's machine and budget, and per
                      network its target, checkpoint sha256, images seen, throughput
``metrics.json``      the run (:data:`METRICS_FIELDS`): machine, budget, phases,
                      data, probes, per network throughput and heatmap metrics
``curves.csv``        training curves: one row per logged step of either network
``run.log``           the run's log (cut to its last :data:`LOG_BYTES`)
====================  ============================================================
"""

from __future__ import annotations

import json
import math
import re
from pathlib import Path

import numpy as np

from vnrrt.data.heatmaps import HeatmapError, part_file, part_rows, read_heatmaps, write_heatmaps
from vnrrt.data.instances import Instances  # the one import of the instances format
from vnrrt.infra.io import sha256

MAX_FILES, MAX_DEPTH = 8, 2
MAX_FILE_BYTES, MAX_TOTAL_BYTES = 16 << 20, 64 << 20
PART_RAW_BYTES = 14 << 20  # raw float16 bytes per heatmap part: compressed it stays < 16 MiB
LOG_BYTES = 1 << 20
OTHER_FILES = ("metrics.json", "curves.csv", "run.log")
NETWORKS = {"paper_vertexnet": "vertexnet", "paper_nrrtnet": "nrrtnet"}  # returned: trained
HEATMAPS_DIR = "heatmaps"
NETWORK_META = ("target", "checkpoint_sha256", "images_seen", "train_images_per_s",
                "infer_images_per_s", "batch_size")  # fmt: skip
RUN_META = ("machine", "budget_s", "networks", "part", "parts")
METRICS_FIELDS = ("machine", "budget_s", "elapsed_s", "phases", "data", "probe", "networks",
                  "source")  # fmt: skip
_NAME = re.compile(r"^[A-Za-z0-9._-]+$")


class ReturnedError(ValueError):
    """A returned file breaks the machine's limits or the schema; the message names it."""


def heatmap_parts(n: int, size: int, networks: int) -> int:
    """Parts needed for ``n`` heatmaps ``(size, size)`` float16 of ``networks`` networks so
    that each part's raw bytes stay under :data:`PART_RAW_BYTES`; :class:`ReturnedError`
    when they cannot fit beside :data:`OTHER_FILES` in the limits."""
    raw = n * size * size * 2 * networks
    parts = max(1, math.ceil(raw / PART_RAW_BYTES))
    if parts + len(OTHER_FILES) > MAX_FILES or raw + 2 * LOG_BYTES > MAX_TOTAL_BYTES:
        raise ReturnedError(
            f"{n} heatmaps of {size}x{size} for {networks} networks ({raw / 2**20:.0f} MiB) do "
            f"not fit the return limits ({MAX_FILES} files, {MAX_TOTAL_BYTES >> 20} MiB): "
            "use an instances file with fewer instances"
        )
    return parts


def write_returned_heatmaps(out: str | Path, keys: np.ndarray, maps: dict[str, np.ndarray],
                            networks: dict[str, dict], **meta) -> list[Path]:  # fmt: skip
    """Write ``maps`` {network: (N, S, S)} of ``keys`` (N, 2) as :func:`heatmap_parts` parts
    ``out/heatmaps/part_<k>.npz`` (meta: ``networks``, ``part``, ``parts`` and ``meta``);
    their sizes are bounded before writing and checked after."""
    n, size = len(keys), next(iter(maps.values())).shape[-1]
    parts = heatmap_parts(n, size, len(maps))
    files = []
    for k in range(parts):
        rows = part_rows(n, k, parts)
        path = part_file(Path(out) / HEATMAPS_DIR, k)
        write_heatmaps(path, keys[rows], {name: m[rows] for name, m in maps.items()},
                       networks=networks, part=k, parts=parts, **meta)  # fmt: skip
        if path.stat().st_size > MAX_FILE_BYTES:
            raise ReturnedError(f"{path} has {path.stat().st_size} bytes > {MAX_FILE_BYTES}")
        files.append(path)
    return files


def check_limits(folder: str | Path) -> dict[str, int]:
    """``{relative path: bytes}`` of every file under ``folder``; :class:`ReturnedError`
    naming the first file or count that breaks the limits (module doc)."""
    folder = Path(folder)
    files = {p.relative_to(folder).as_posix(): p.stat().st_size
             for p in sorted(folder.rglob("*")) if p.is_file()}  # fmt: skip
    for name, size in files.items():
        parts = name.split("/")
        if len(parts) > MAX_DEPTH + 1 or not all(_NAME.match(p) for p in parts):
            raise ReturnedError(f"returned file {name!r}: too deep or a name the machine drops")
        if size > MAX_FILE_BYTES:
            raise ReturnedError(f"returned file {name!r} has {size} bytes > {MAX_FILE_BYTES}")
    if len(files) > MAX_FILES or sum(files.values()) > MAX_TOTAL_BYTES:
        raise ReturnedError(
            f"{folder}: {len(files)} files, {sum(files.values())} bytes; the machine returns "
            f"at most {MAX_FILES} files and {MAX_TOTAL_BYTES} bytes"
        )
    return files


def _check_meta(meta: dict, where: str) -> None:
    missing = [k for k in RUN_META if k not in meta]
    if missing:
        raise ReturnedError(f"{where}: meta lacks {missing}")
    if sorted(meta["networks"]) != sorted(NETWORKS):
        raise ReturnedError(f"{where}: meta networks {sorted(meta['networks'])}, "
                            f"expected {sorted(NETWORKS)}")  # fmt: skip
    for name, entry in meta["networks"].items():
        lacks = [k for k in NETWORK_META if k not in entry]
        if lacks:
            raise ReturnedError(f"{where}: meta of {name} lacks {lacks}")
        if entry["target"].get("kind") not in ("vertex", "path"):
            raise ReturnedError(f"{where}: {name} target kind {entry['target'].get('kind')!r}")
        if not re.fullmatch(r"[0-9a-f]{64}", str(entry["checkpoint_sha256"])):
            raise ReturnedError(f"{where}: {name} checkpoint_sha256 is not a sha256")
        if not int(entry["images_seen"]) > 0:
            raise ReturnedError(f"{where}: {name} saw no training images")


def _check_maps(maps: dict[str, np.ndarray], n: int, size: int, where: str) -> None:
    if sorted(maps) != sorted(NETWORKS):
        raise ReturnedError(f"{where}: networks {sorted(maps)}, expected {sorted(NETWORKS)}")
    for name, heat in maps.items():
        if heat.dtype != np.float16 or heat.shape != (n, size, size):
            raise ReturnedError(f"{where}: {name} is {heat.dtype} {heat.shape}, "
                                f"expected float16 {(n, size, size)}")  # fmt: skip
        values = heat.astype(np.float32)
        if not np.isfinite(values).all() or values.min(initial=0) < 0 or values.max(initial=0) > 1:
            raise ReturnedError(f"{where}: {name} has values that are not finite in [0, 1]")


def _part_files(path: Path) -> list[Path]:
    """The heatmap files of a returned folder (``heatmaps/part_<k>.npz``, ``k`` in
    0..parts-1 by the first part's meta), a heatmaps folder, or one heatmap file."""
    if path.is_file():
        return [path]
    folder = path / HEATMAPS_DIR if (path / HEATMAPS_DIR).is_dir() else path
    first = read_heatmaps(part_file(folder, 0))
    return [part_file(folder, k) for k in range(int(first["meta"].get("parts", 1)))]


def read_returned(path: str | Path, instances: Instances | str | Path) -> dict:
    """The returned heatmaps of ``path`` (a returned folder, its ``heatmaps`` folder or one
    heatmap file), checked against ``instances`` (an :class:`Instances` or its file).

    Returns :func:`vnrrt.data.heatmaps.read_parts`'s dict (``keys`` (N, 2), ``maps``
    {network: (N, S, S) float16}, ``meta`` one dict per part, ``counts``) plus ``metrics``
    (``metrics.json`` of a returned folder, which must be there and name the sha256 of
    ``instances``' file; None for a heatmaps folder or file). :class:`ReturnedError` (or
    :class:`~vnrrt.data.heatmaps.HeatmapError`) in one line naming what is wrong: limits,
    format, keys not those of the instances in order, shapes, dtype, values, meta fields.
    """
    path = Path(path)
    inst = instances if isinstance(instances, Instances) else Instances(instances)
    if path.is_dir():
        check_limits(path)
    files = [read_heatmaps(f) for f in _part_files(path)]
    keys = np.concatenate([f["keys"] for f in files])
    if not np.array_equal(keys, inst.keys):
        raise ReturnedError(f"{path}: heatmap keys are not the keys of {inst.path} in order "
                            f"({len(keys)} vs {len(inst.keys)} instances)")  # fmt: skip
    for k, f in enumerate(files):
        where = f"{path} part {k}"
        _check_meta(f["meta"], where)
        if int(f["meta"]["part"]) != k or int(f["meta"]["parts"]) != len(files):
            raise ReturnedError(f"{where}: meta says part {f['meta']['part']} of "
                                f"{f['meta']['parts']}, found {len(files)} parts")  # fmt: skip
        _check_maps(f["maps"], len(f["keys"]), inst.size, where)
    returned = path.is_dir() and (path / HEATMAPS_DIR).is_dir()  # the whole output folder
    metrics = _read_metrics(path / "metrics.json", inst) if returned else None
    return {
        "keys": keys,
        "maps": {n: np.concatenate([f["maps"][n] for f in files]) for n in NETWORKS},
        "meta": [f["meta"] for f in files],
        "counts": [len(f["keys"]) for f in files],
        "metrics": metrics,
    }


def _read_metrics(path: Path, inst: Instances) -> dict:
    """The run's metrics; the instances file it predicted must be ``inst``'s (sha256)."""
    if not path.is_file():
        raise ReturnedError(f"{path} is missing: the run did not finish")
    try:
        doc = json.loads(path.read_text())
    except json.JSONDecodeError as err:
        raise ReturnedError(f"{path} is not valid JSON: {err}") from None
    missing = [k for k in METRICS_FIELDS if k not in doc]
    if missing:
        raise ReturnedError(f"{path} lacks {missing}")
    if doc["source"].get("instances_sha256") != sha256(inst.path):
        raise ReturnedError(f"{path}: the run predicted another instances file than "
                            f"{inst.path} (sha256 differs)")  # fmt: skip
    return doc


__all__ = [
    "HeatmapError",
    "Instances",
    "ReturnedError",
    "check_limits",
    "read_returned",
    "write_returned_heatmaps",
]
