"""The inputs of the ``vnrrt`` command line: map files (:func:`load_instance`) and heatmap
files (:func:`load_heatmap`), read and checked against each other (formats in
:mod:`vnrrt.cli.main`). Every problem raises :class:`UsageError` (or the reader's own error type)
naming the file."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from vnrrt.infra.io import load_npy


class UsageError(ValueError):
    """A command-line argument is wrong; the message names it."""


def _read_image(path: Path) -> np.ndarray:
    """A heatmap PNG's gray levels ``(H, W)`` float64 in [0, 1] (any bit depth)."""
    from vnrrt.maps.image import decode_png

    gray, _, full = decode_png(path)
    return gray.astype(np.float64) / full


def _shard_instance(path: Path, instance: str | None) -> dict:
    from vnrrt.data.reader import Shard

    if instance is None:
        raise UsageError(f"{path} holds many instances: give --instance (an index or a name)")
    shard = Shard(path)
    _verify_against_manifest(path)
    names = list(shard.meta.get("names", []))
    if instance in names:
        index = names.index(instance)
    elif instance.lstrip("-").isdigit():
        index = int(instance)
    else:
        known = f"; names: {', '.join(names)}" if names else ""
        raise UsageError(f"--instance {instance!r} is not an index of {path}{known}")
    if not 0 <= index < shard.n_instances:
        raise UsageError(f"--instance {index} not in [0, {shard.n_instances}) of {path}")
    inst = shard.instance(index)
    s, g = inst["start"], inst["goal"]
    return {"grid": shard.grid(inst["map_index"]), "start": (s[0] + 0.5, s[1] + 0.5),
            "goal": (g[0] + 0.5, g[1] + 0.5), "astar": inst["length"], "index": index,
            "key": (int(shard.meta.get("shard", -1)), index)}  # fmt: skip


def _verify_against_manifest(path: Path) -> None:
    """A shard beside a pipeline manifest (``../manifest.json``) must match its checksum."""
    from vnrrt.data.manifest import verify_manifest

    manifest = path.parent.parent / "manifest.json"
    if manifest.is_file() and path.parent.name == "shards":
        listed = {p.resolve() for p in verify_manifest(manifest)}
        if path.resolve() not in listed:
            raise UsageError(f"{path} is not listed in {manifest}")


# The first bytes of each kind of file the commands write (``--out``).
MAGIC = {".png": b"\x89PNG\r\n\x1a\n", ".npy": b"\x93NUMPY"}


def check_out(path: Path, suffixes: tuple[str, ...]) -> None:
    """Refuse an ``--out`` that the command would not write as asked: a name not ending in
    one of ``suffixes`` (the kinds it writes, keys of :data:`MAGIC`), a directory, a folder
    that does not exist, or an existing file of another kind (its first bytes are not
    those of its suffix's format): such a file is the user's, never overwritten."""
    kinds = " or ".join(suffixes)
    if path.is_dir():
        raise UsageError(f"--out {path} is a directory; give a {kinds} file name")
    if path.suffix.lower() not in suffixes:
        raise UsageError(f"--out {path}: give a {kinds} file name (it writes {kinds} only)")
    if not path.parent.is_dir():
        raise UsageError(f"--out {path}: directory {path.parent} does not exist (create it)")
    if path.exists():
        magic = MAGIC[path.suffix.lower()]
        with open(path, "rb") as f:
            if f.read(len(magic)) != magic:
                raise UsageError(f"--out {path} exists and is not a {path.suffix} file; "
                                 "not overwriting it (move it or choose another name)")  # fmt: skip


def load_instance(path: Path, instance: str | None) -> dict:
    """Grid ``(H, W)`` uint8 and, where the file holds them, start/goal points and the A*
    length (formats in the module doc)."""
    if not path.is_file():
        raise UsageError(f"map file {path} not found")
    if path.suffix == ".npz":
        return _shard_instance(path, instance)
    if instance is not None:
        raise UsageError(f"--instance needs a shard or named-maps .npz, not {path.suffix}")
    if path.suffix == ".npy":
        return {"grid": load_npy(path, "map file", UsageError)}
    if path.suffix == ".map":  # MovingAI (vnrrt.maps.movingai): the grid only
        from vnrrt.maps.movingai import read_map

        return {"grid": read_map(path)}
    if path.suffix == ".png":
        from vnrrt.maps.image import read_map_image

        return {k: v for k, v in read_map_image(path).items() if v is not None}
    raise UsageError(f"unsupported map file {path}: use .npy, .png, .map or a shard .npz")


def load_heatmap(
    path: Path,
    key: tuple[int, int] | None = None,
    network: str | None = None,
    row: int | None = None,
    planner: str | None = None,
) -> np.ndarray:
    """Heatmap ``(H, W)`` float64 from ``.npy``, a grayscale ``.png`` (scaled to [0, 1]) or a
    pipeline heatmap file (``.npz``: ``network``'s heatmap of the instance ``key`` = (shard
    id, instance index; -1 for the named maps), or of ``row`` when the map has no key; both
    given must agree, so that a heatmap of another instance is never used; ``network`` must
    have the target ``planner`` samples, when given)."""
    if not path.is_file():
        raise UsageError(f"heatmap file {path} not found")
    if path.suffix == ".npy":
        return np.load(path).astype(np.float64)
    if path.suffix == ".map":  # MovingAI (vnrrt.maps.movingai): the grid only
        from vnrrt.maps.movingai import read_map

        return {"grid": read_map(path)}
    if path.suffix == ".png":
        return _read_image(path)
    if path.suffix == ".npz":
        from vnrrt.data.heatmaps import read_heatmaps

        heat = read_heatmaps(path)
        nets = sorted(heat["maps"])
        if network not in heat["maps"]:
            raise UsageError(f"give --network, one of {nets} in {path}")
        check_planner_target(heat["meta"].get("networks", {}).get(network, {}), planner,
                      f"{network} of {path}")  # fmt: skip
        return heat["maps"][network][_heat_row(heat["keys"], path, key, row)].astype(np.float64)
    raise UsageError(f"unsupported heatmap file {path}: use .npy, .png or a pipeline .npz")


def check_planner_target(record: dict, planner: str | None, source: str) -> None:
    """Refuse a network (its ``record``) whose target is not the one ``planner`` samples."""
    from vnrrt.data.targets import PLANNER_TARGETS

    if planner in PLANNER_TARGETS:
        from vnrrt.model.checkpoint import require_target

        require_target(
            record, PLANNER_TARGETS[planner], source, f"that --planner {planner} samples"
        )


def _heat_row(keys: np.ndarray, path: Path, key, row: int | None) -> int:
    """The row of a heatmap file's ``keys`` (N, 2) for instance ``key`` and/or ``row``."""
    if row is not None and not 0 <= row < len(keys):
        raise UsageError(f"--row {row} is not one of the {len(keys)} rows of {path}")
    if key is None:
        if row is None:
            raise UsageError(f"give --row: which of the {len(keys)} heatmaps of {path}")
        return row
    hits = np.flatnonzero((keys == np.asarray(key)).all(axis=1))
    if not len(hits):
        raise UsageError(f"{path} holds no heatmap of instance {tuple(key)} (shard, index) of "
                         "--map: use the heatmap file (part) that covers it")  # fmt: skip
    if row is not None and row != hits[0]:
        raise UsageError(f"--row {row} of {path} is instance {tuple(keys[row])}, not the "
                         f"--map instance {tuple(key)} (row {hits[0]})")  # fmt: skip
    return int(hits[0])
