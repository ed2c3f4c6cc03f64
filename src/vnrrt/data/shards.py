"""The shard file format (version 1): one compact, deterministic ``.npz`` per shard.

A shard holds ``M`` base maps (stored once, bit-packed) and their ``N`` instances
(start x goal pairs). Named fields (``M`` maps, ``N`` instances, ``S`` map size):

=================  ================  ==================================================
field              shape, dtype      meaning
=================  ================  ==================================================
``format_version`` (), int64         :data:`FORMAT_VERSION`
``meta``           (), str           JSON: seed, shard id, config used
``map_ids``        (M,), int64       global map id (``shard * maps_per_shard + j``)
``split``          (M,), uint8       0 = train, 1 = test (split is by base map)
``maps``           (M, S, ceil(S/8)) occupancy bits, ``np.packbits`` along x
``starts``         (M, n_s, 2) u16   start cells (x, y) of each map
``goals``          (M, n_g, 2) u16   goal cells (x, y) of each map
``inst_map``       (N,), int32       local map index of each instance
``inst_start``     (N, 2), uint16    start cell (x, y)
``inst_goal``      (N, 2), uint16    goal cell (x, y)
``inst_length``    (N,), float64     optimal 8-connected octile length (pixels)
``path_offsets``   (N+1,), int64     instance i's moves: ``path_moves[o[i]:o[i+1]]``
``path_moves``     (P,), uint8       chain codes into :data:`vnrrt.grid.MOVES`
``vertex_offsets`` (N+1,), int64     instance i's vertices: ``vertex_steps[o[i]:o[i+1]]``
``vertex_steps``   (V,), uint32      vertex positions as indices into the path's cells
=================  ================  ==================================================

Files are zip archives written with fixed timestamps, so their bytes depend only on the
arrays; writes go to a temporary file that is renamed into place (atomic).
"""

from __future__ import annotations

import json
import zipfile
from pathlib import Path

import numpy as np

from vnrrt.config.paths import shard_file  # noqa: F401  (re-exported)
from vnrrt.infra.io import atomic_write_bytes, load_npz

FORMAT_VERSION = 1
FIELDS = {
    "format_version": ((), "int64"),
    "meta": ((), "str"),
    "map_ids": (("M",), "int64"),
    "split": (("M",), "uint8"),
    "maps": (("M", None, None), "uint8"),
    "starts": (("M", None, 2), "uint16"),
    "goals": (("M", None, 2), "uint16"),
    "inst_map": (("N",), "int32"),
    "inst_start": (("N", 2), "uint16"),
    "inst_goal": (("N", 2), "uint16"),
    "inst_length": (("N",), "float64"),
    "path_offsets": (("N+1",), "int64"),
    "path_moves": ((None,), "uint8"),
    "vertex_offsets": (("N+1",), "int64"),
    "vertex_steps": ((None,), "uint32"),
}


class ShardError(ValueError):
    """A shard file is missing, corrupt or of another format; the message names the file."""


def write_shard(path: str | Path, arrays: dict[str, np.ndarray]) -> None:
    """Validate ``arrays`` against :data:`FIELDS` and write them deterministically."""
    _check_fields(Path(path), arrays)

    def write(f):
        with zipfile.ZipFile(f, "w", compression=zipfile.ZIP_DEFLATED, compresslevel=6) as zf:
            for name in FIELDS:
                info = zipfile.ZipInfo(f"{name}.npy", date_time=(1980, 1, 1, 0, 0, 0))
                info.compress_type = zipfile.ZIP_DEFLATED
                info.external_attr = 0o644 << 16
                with zf.open(info, "w", force_zip64=True) as member:
                    arr = np.asarray(arrays[name], order="C")  # keeps 0-d fields 0-d
                    np.lib.format.write_array(member, arr, allow_pickle=False)

    atomic_write_bytes(Path(path), write)


def read_arrays(path: str | Path) -> dict[str, np.ndarray]:
    """Load and validate all fields of a shard file; :class:`ShardError` if anything is off."""
    path = Path(path)
    if not path.is_file():
        raise ShardError(f"shard file {path} does not exist")
    arrays = load_npz(path, "shard file", ShardError)
    version = arrays.get("format_version")
    if version is None or int(version) != FORMAT_VERSION:
        raise ShardError(
            f"shard file {path} has format version {version}, this code reads {FORMAT_VERSION}"
        )
    _check_fields(path, arrays)
    return arrays


def _check_fields(path: Path, arrays: dict[str, np.ndarray]) -> None:
    missing = [k for k in FIELDS if k not in arrays]
    if missing:
        raise ShardError(f"shard {path} lacks fields {missing}")
    dims = {"M": len(arrays["map_ids"]), "N": len(arrays["inst_map"])}
    dims["N+1"] = dims["N"] + 1
    for name, (shape, dtype) in FIELDS.items():
        arr = np.asarray(arrays[name])
        ok_dtype = arr.dtype.kind == "U" if dtype == "str" else arr.dtype == np.dtype(dtype)
        want = tuple(dims.get(d, d) if isinstance(d, str) else d for d in shape)
        ok_shape = arr.ndim == len(want) and all(w in (None, a) for w, a in zip(want, arr.shape))
        if not (ok_dtype and ok_shape):
            raise ShardError(
                f"shard {path}: field {name!r} has shape {arr.shape} dtype {arr.dtype}, "
                f"expected shape {want} dtype {dtype}"
            )
    for offs, flat in (("path_offsets", "path_moves"), ("vertex_offsets", "vertex_steps")):
        o = arrays[offs]
        if o[0] != 0 or o[-1] != len(arrays[flat]) or np.any(np.diff(o) < 0):
            raise ShardError(f"shard {path}: {offs} do not index {flat} consistently")


def meta_json(**meta) -> np.ndarray:
    """The ``meta`` field: canonical JSON (sorted keys) as a 0-d unicode array."""
    return np.array(json.dumps(meta, sort_keys=True))
