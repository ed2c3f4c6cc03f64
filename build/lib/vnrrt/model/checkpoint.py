"""Checkpoints of trained networks: checking them before resuming, loading them to predict.

A checkpoint is Lightning's file plus a ``"vnrrt"`` record (:func:`vnrrt.train.make_record`):
the network's config (``_target_`` style), its target and the input rendering. A checkpoint is
only ever used from an explicit path (config or DVC stage), never found by globbing. Every
problem raises :class:`CheckpointError` naming the file and what is wrong.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import torch
from hydra.utils import instantiate
from torch import nn

from vnrrt.model.module import RECORD_KEY

RECORD_FIELDS = ("network", "net", "target", "render")
CHECKSUM_SUFFIX = ".sha256"  # <checkpoint>.sha256 beside each checkpoint the pipeline writes


class CheckpointError(ValueError):
    """A checkpoint is missing, unreadable or does not fit the network it is used for."""


def checksum_file(path: str | Path) -> Path:
    """``<checkpoint>.sha256``: the checkpoint's recorded sha256."""
    return Path(f"{path}{CHECKSUM_SUFFIX}")


def write_checksum(path: str | Path) -> str:
    """Record the checkpoint's sha256 beside it; returns the digest."""
    from vnrrt.io import sha256, write_text

    digest = sha256(path)
    write_text(checksum_file(path), f"{digest}  {Path(path).name}\n")
    return digest


def verify_checksum(path: str | Path, required: bool = False) -> None:
    """Raise :class:`CheckpointError` when the checkpoint's bytes do not match its recorded
    sha256 (a corrupted or swapped file), or when ``required`` and none is recorded."""
    from vnrrt.io import sha256

    record = checksum_file(path)
    if not record.is_file():
        if required:
            raise CheckpointError(f"checkpoint {path} has no recorded sha256 ({record})")
        return
    want = record.read_text().split()[0] if record.read_text().split() else ""
    if sha256(path) != want:
        raise CheckpointError(f"checkpoint {path} does not match its recorded sha256 ({record}): "
                              "the file was modified or corrupted")  # fmt: skip


def read_checkpoint(path: str | Path, verify: bool = False) -> dict[str, Any]:
    """Load a checkpoint file on CPU (tensors and plain data only) and check its record; its
    recorded sha256 too, where there is one (``verify``: there must be one)."""
    path = Path(path)
    if not path.is_file():
        raise CheckpointError(f"checkpoint {path} does not exist")
    verify_checksum(path, required=verify)
    try:
        ckpt = torch.load(path, map_location="cpu", weights_only=True)
    except Exception as err:  # torch raises many types for corrupt or foreign files
        raise CheckpointError(f"checkpoint {path} is unreadable: {err}") from None
    if not isinstance(ckpt, dict) or "state_dict" not in ckpt:
        raise CheckpointError(f"checkpoint {path} is not a Lightning checkpoint (no state_dict)")
    record = ckpt.get(RECORD_KEY)
    if not isinstance(record, dict) or any(k not in record for k in RECORD_FIELDS):
        raise CheckpointError(
            f"checkpoint {path} has no vnrrt record {RECORD_FIELDS}: not written by vnrrt.train"
        )
    return ckpt


def _differences(saved: Any, wanted: Any, where: str) -> list[str]:
    """``key: checkpoint X, config Y`` for every leaf where two nested records differ."""
    if isinstance(saved, dict) and isinstance(wanted, dict):
        out = []
        for key in sorted(set(saved) | set(wanted), key=str):
            out += _differences(saved.get(key), wanted.get(key), f"{where}.{key}")
        return out
    return [] if saved == wanted else [f"{where}: checkpoint {saved!r}, config {wanted!r}"]


def check_state_dict(path: Path, state: dict, model: nn.Module) -> None:
    """Raise :class:`CheckpointError` listing missing, unexpected and mis-shaped weights."""
    expected = {k: tuple(v.shape) for k, v in model.state_dict().items()}
    missing = sorted(set(expected) - set(state))
    unexpected = sorted(set(state) - set(expected))
    shapes = [f"{k} {tuple(state[k].shape)} vs {expected[k]}" for k in expected
              if k in state and tuple(state[k].shape) != expected[k]]  # fmt: skip
    problems = [f"{name}: {', '.join(keys[:6])}{' ...' if len(keys) > 6 else ''}"
                for name, keys in (("missing", missing), ("unexpected", unexpected),
                                   ("shape mismatch", shapes)) if keys]  # fmt: skip
    if problems:
        raise CheckpointError(f"checkpoint {path} does not fit the network: " + "; ".join(problems))


def check_checkpoint(path: str | Path, record: dict, module: nn.Module) -> dict[str, Any]:
    """Check that checkpoint ``path`` can resume training of ``module`` configured as
    ``record`` (same network, network config, target and rendering, fitting weights)."""
    ckpt = read_checkpoint(path)
    saved = {k: ckpt[RECORD_KEY][k] for k in RECORD_FIELDS}
    diffs = _differences(saved, {k: record[k] for k in RECORD_FIELDS}, "record")
    if diffs:
        raise CheckpointError(
            f"checkpoint {path} was trained with another configuration: " + "; ".join(diffs)
        )
    check_state_dict(Path(path), ckpt["state_dict"], module)
    return ckpt


def load_network(
    path: str | Path, network: str | None = None, verify: bool = False
) -> tuple[nn.Module, dict]:
    """The trained network ``(B, 3, H, W) -> (B, 2, H, W)`` logits of checkpoint ``path``
    (eval mode, CPU) and its record. ``network`` checks the record's network name;
    ``verify`` requires a recorded sha256 that matches (:func:`verify_checksum`)."""
    ckpt = read_checkpoint(path, verify)
    record = ckpt[RECORD_KEY]
    if network is not None and record["network"] != network:
        raise CheckpointError(f"checkpoint {path} holds {record['network']!r}, not {network!r}")
    net_cfg = dict(record["net"], weights=None, freeze_encoder=False)  # weights come from here
    net = instantiate(net_cfg)
    prefix = "net."
    state = {k[len(prefix) :]: v for k, v in ckpt["state_dict"].items() if k.startswith(prefix)}
    check_state_dict(Path(path), state, net)
    net.load_state_dict(state)
    return net.eval(), record
