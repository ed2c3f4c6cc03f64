"""Small file helpers shared by every stage: atomic writes, JSON, checksums, and the readers
of ``.npz``, ``.npy`` and YAML files whose decode errors name the file.

Every output of the pipeline is written to a temporary file beside its destination and
renamed into place, so an interrupted run never leaves a half-written file under the real
name. Temporary files are named ``<name>.tmp-<pid>``: ``.dvcignore`` and ``.gitignore``
ignore them, and a later write to the same destination removes the ones a killed process
left behind.
"""

from __future__ import annotations

import hashlib
import json
import os
import struct
import zipfile
import zlib
from collections.abc import Callable
from pathlib import Path
from typing import IO, Any

TMP_MARK = ".tmp-"
# What reading a damaged or foreign file raises (a flipped byte, a truncation, another
# format): zip and deflate errors of .npz and .gz members, numpy's format errors, a header
# read as a huge shape (MemoryError), an unknown compression method (NotImplementedError).
DECODE_ERRORS = (OSError, ValueError, EOFError, KeyError, zipfile.BadZipFile, zlib.error,
                 struct.error, NotImplementedError, MemoryError)  # fmt: skip


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:  # exists, owned by someone else
        return True
    return True


def remove_stale_temps(path: str | Path) -> list[Path]:
    """Delete ``<path>.tmp-<pid>`` files beside ``path`` whose process no longer runs;
    returns the removed paths."""
    path = Path(path)
    removed = []
    if not path.parent.is_dir():
        return removed
    for tmp in path.parent.glob(f"{path.name}{TMP_MARK}*"):
        pid = tmp.name.rsplit(TMP_MARK, 1)[-1]
        if not pid.isdigit() or not _alive(int(pid)):
            tmp.unlink(missing_ok=True)
            removed.append(tmp)
    return removed


def atomic_write_bytes(path: str | Path, write: Callable[[IO[bytes]], Any]) -> None:
    """Call ``write(file)`` on a temp file beside ``path``, fsync, then rename into place."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    if path.is_dir():
        raise IsADirectoryError(f"{path} is a directory, expected a file path")
    remove_stale_temps(path)
    tmp = path.with_name(f"{path.name}{TMP_MARK}{os.getpid()}")
    try:
        with open(tmp, "wb") as f:
            write(f)
            f.flush()
            os.fsync(f.fileno())
        os.replace(tmp, path)
    finally:
        tmp.unlink(missing_ok=True)


def write_text(path: str | Path, text: str) -> None:
    """Write ``text`` (UTF-8) atomically."""
    atomic_write_bytes(path, lambda f: f.write(text.encode()))


def write_json(path: str | Path, obj: Any) -> None:
    """Write ``obj`` as indented JSON with sorted keys, atomically."""
    write_text(path, json.dumps(obj, indent=2, sort_keys=True) + "\n")


def read_json(path: str | Path) -> Any:
    """The JSON document in ``path``; ``FileNotFoundError`` / ``ValueError`` name the file."""
    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"{path} does not exist")
    try:
        return json.loads(path.read_text())
    except (json.JSONDecodeError, UnicodeDecodeError) as err:
        raise ValueError(f"{path} is not valid JSON: {err}") from None


def read_yaml(path: str | Path, what: str, error: type[Exception] = ValueError) -> Any:
    """The YAML document in ``path`` (``what`` it is, for the message); ``error`` naming the
    file when it is missing, not UTF-8 text or not YAML."""
    import yaml

    path = Path(path)
    if not path.is_file():
        raise error(f"{what} {path} does not exist")
    try:
        return yaml.safe_load(path.read_text())
    except (yaml.YAMLError, UnicodeDecodeError) as err:
        why = " ".join(str(err).split())
        raise error(f"{what} {path} is not valid YAML: {why}") from None


def load_npz(path: str | Path, what: str, error: type[Exception] = ValueError) -> dict:
    """Every array of the ``.npz`` file ``path`` (``what`` it is), decoded now: ``{name:
    array}``; ``error`` naming the file on any decode error (:data:`DECODE_ERRORS`) and on
    pickled (object) arrays, which are never read."""
    import numpy as np

    try:
        with open(path, "rb") as f:
            if f.read(4) != b"PK\x03\x04":
                raise ValueError("not an .npz file (no zip header)")
        with np.load(path, allow_pickle=False) as npz:
            return {k: npz[k] for k in npz.files}
    except DECODE_ERRORS as err:
        raise error(
            f"{what} {path} is not a readable .npz: {_why(err)} (corrupt or another format)"
        ) from None


def load_npy(path: str | Path, what: str, error: type[Exception] = ValueError):
    """The array of the ``.npy`` file ``path`` (``what`` it is); ``error`` naming the file on
    any decode error, on another format and on pickled (object) arrays."""
    import numpy as np

    try:
        with open(path, "rb") as f:
            if f.read(6) != b"\x93NUMPY":
                raise ValueError("not a .npy file (no NumPy header)")
            f.seek(0)
            return np.load(f, allow_pickle=False)
    except DECODE_ERRORS as err:
        raise error(
            f"{what} {path} is not a readable .npy: {_why(err)} (corrupt or another format)"
        ) from None


def _why(err: BaseException) -> str:
    """``err`` in a few words: its first line, its type where it has no message; numpy's
    advice to unpickle is replaced by what it means here."""
    text = " ".join(str(err).split()) or type(err).__name__
    if "allow_pickle" in text:
        return "it holds pickled Python objects, which are never loaded"
    return (
        text if not isinstance(err, zlib.error | MemoryError) else f"{type(err).__name__}: {text}"
    )


def file_digest(path: str | Path, algorithm: str = "sha256") -> str:
    """Hex digest of a file's bytes (``algorithm``: a ``hashlib`` name)."""
    h = hashlib.new(algorithm)
    with open(path, "rb") as f:
        for block in iter(lambda: f.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


def sha256(path: str | Path) -> str:
    """Hex sha256 of a file's bytes."""
    return file_digest(path, "sha256")
