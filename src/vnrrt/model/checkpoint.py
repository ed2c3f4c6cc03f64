"""Checkpoints of trained networks: checking them before resuming, loading them to predict.

A checkpoint is Lightning's file plus a ``"vnrrt"`` record
(:func:`vnrrt.pipeline.training.make_record`): the network's config, its target, the input
rendering and a sha256 of the record and the weights (:func:`vnrrt.model.record.record_digest`,
written when the file is saved). A
checkpoint is only ever used from an explicit path (config or DVC stage), never found by
globbing.

Loading is safe and checked: the file is read with ``torch.load(weights_only=True)``
(tensors and plain data, no code), and the network is always a
:class:`~vnrrt.model.VertexNet` built from the record's arguments after checking each one
(:data:`NET_ARGS`; the record's ``_target_`` must name that class, it is never imported or
called). The weights must match the digest stored in the record, and be finite. A checkpoint
written before records carried a digest loads only when the ``.sha256`` file beside it
matches. Every problem raises :class:`CheckpointError`, one line naming the file and what
is wrong.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import torch
from torch import nn

from vnrrt.data.targets import TARGETS
from vnrrt.model.record import DIGEST_KEY, RECORD_KEY, record_digest
from vnrrt.model.resnet import LAYERS
from vnrrt.model.vertexnet import VertexNet

RECORD_FIELDS = ("network", "net", "target", "render")
CHECKSUM_SUFFIX = ".sha256"  # <checkpoint>.sha256 beside each checkpoint the pipeline writes
NETWORK_CLASS = "vnrrt.model.VertexNet"  # the one network class a checkpoint may hold
RETRAIN = "retrain it (`dvc repro train@<network>`)"


def _real(v: Any) -> bool:
    return isinstance(v, int | float) and not isinstance(v, bool) and math.isfinite(v)


def _count(v: Any, low: int, high: int) -> bool:
    return isinstance(v, int) and not isinstance(v, bool) and low <= v <= high


# VertexNet's arguments a checkpoint may set: (check of the value, what the check asks).
NET_ARGS = {
    "encoder": (lambda v: v in LAYERS, f"one of {sorted(LAYERS)}"),
    "out_channels": (lambda v: _count(v, 2, 16), "an integer in [2, 16]"),
    "in_channels": (lambda v: _count(v, 1, 16), "an integer in [1, 16]"),
    "decoder_width": (lambda v: _real(v) and 0 < v <= 4, "a number in (0, 4]"),
    "encoder_width": (lambda v: _real(v) and 0 < v <= 4, "a number in (0, 4]"),
    "prior": (lambda v: v is None or (_real(v) and 0 < v < 1), "null or a number in (0, 1)"),
}
TRAINING_ARGS = ("weights", "freeze_encoder")  # settings of training only: ignored on load


class CheckpointError(ValueError):
    """A checkpoint is missing, unreadable, modified or does not fit the network it is used
    for; the message (one line) names the file and the problem."""


def _first_line(err: BaseException) -> str:
    text = str(err).strip()
    return text.splitlines()[0] if text else type(err).__name__


def checksum_file(path: str | Path) -> Path:
    """``<checkpoint>.sha256``: the checkpoint's recorded sha256."""
    return Path(f"{path}{CHECKSUM_SUFFIX}")


def write_checksum(path: str | Path) -> str:
    """Record the checkpoint's sha256 beside it; returns the digest."""
    from vnrrt.infra.io import sha256, write_text

    digest = sha256(path)
    write_text(checksum_file(path), f"{digest}  {Path(path).name}\n")
    return digest


def verify_checksum(path: str | Path, required: bool = False) -> None:
    """Raise :class:`CheckpointError` when the checkpoint's bytes do not match its recorded
    sha256 (a corrupted or swapped file), or when ``required`` and none is recorded."""
    from vnrrt.infra.io import sha256

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
    """Load a checkpoint file on CPU (tensors and plain data only) and check its record, its
    digest and its weights (module doc); its ``.sha256`` file too, where there is one
    (``verify``: there must be one)."""
    path = Path(path)
    if not path.is_file():
        raise CheckpointError(f"checkpoint {path} does not exist")
    verify_checksum(path, required=verify)
    try:
        ckpt = torch.load(path, map_location="cpu", weights_only=True)
    except Exception as err:  # torch raises many types for corrupt or foreign files
        raise CheckpointError(f"checkpoint {path} is unreadable: {_first_line(err)}") from None
    state = ckpt.get("state_dict") if isinstance(ckpt, dict) else None
    if not isinstance(state, dict):
        raise CheckpointError(f"checkpoint {path} is not a Lightning checkpoint (no state_dict)")
    if not all(isinstance(k, str) and isinstance(v, torch.Tensor) for k, v in state.items()):
        raise CheckpointError(f"checkpoint {path}: its state_dict holds more than named tensors")
    record = ckpt.get(RECORD_KEY)
    if not isinstance(record, dict) or any(k not in record for k in RECORD_FIELDS):
        raise CheckpointError(
            f"checkpoint {path} has no vnrrt record {RECORD_FIELDS}: not written by vnrrt.train"
        )
    check_record(path, record)
    check_digest(path, ckpt)
    check_finite(path, state)
    return ckpt


def check_record(path: Path, record: dict) -> None:
    """Raise :class:`CheckpointError` unless the record's network config, target and
    rendering are values this version can use (:data:`NET_ARGS`, :data:`TARGETS`)."""
    network_kwargs(path, record["net"])
    target = record["target"]
    if not isinstance(target, dict) or target.get("kind") not in TARGETS:
        raise CheckpointError(f"checkpoint {path}: record.target {target!r} has no kind in "
                              f"{TARGETS}")  # fmt: skip
    render = record["render"]
    if (not isinstance(render, dict) or set(render) != {"marker_radius", "normalize"}
            or not (_real(render["marker_radius"]) and render["marker_radius"] >= 0)
            or not isinstance(render["normalize"], str)):  # fmt: skip
        raise CheckpointError(f"checkpoint {path}: record.render {render!r} is not "
                              "{marker_radius: number >= 0, normalize: name}")  # fmt: skip


def network_kwargs(path: Path, net: Any) -> dict[str, Any]:
    """The :class:`VertexNet` arguments of a record's ``net`` config, each checked
    (:data:`NET_ARGS`); training-only settings are dropped."""
    if not isinstance(net, dict) or net.get("_target_") != NETWORK_CLASS:
        got = net.get("_target_") if isinstance(net, dict) else net
        raise CheckpointError(f"checkpoint {path}: record.net names network {got!r}; only "
                              f"{NETWORK_CLASS} is loaded")  # fmt: skip
    kwargs = {}
    for key, value in net.items():
        if key == "_target_" or key in TRAINING_ARGS:
            continue
        if key not in NET_ARGS:
            raise CheckpointError(f"checkpoint {path}: record.net.{key} is not an argument of "
                                  f"{NETWORK_CLASS} ({', '.join(NET_ARGS)})")  # fmt: skip
        ok, wanted = NET_ARGS[key]
        if not ok(value):
            raise CheckpointError(f"checkpoint {path}: record.net.{key}={value!r} is not {wanted}")
        kwargs[key] = value
    return kwargs


def check_digest(path: Path, ckpt: dict) -> None:
    """Raise :class:`CheckpointError` when the record and weights do not match the digest
    stored in the record; a checkpoint without one needs a ``.sha256`` file beside it (which
    :func:`read_checkpoint` has matched)."""
    record = ckpt[RECORD_KEY]
    if DIGEST_KEY not in record:
        if not checksum_file(path).is_file():
            raise CheckpointError(f"checkpoint {path} stores no sha256 of its weights (written "
                                  "before checkpoints carried one) and has no "
                                  f"{CHECKSUM_SUFFIX} file beside it: {RETRAIN}")  # fmt: skip
        return
    if record_digest(record, ckpt["state_dict"]) != record[DIGEST_KEY]:
        raise CheckpointError(f"checkpoint {path}: its weights or record do not match the sha256 "
                              "stored in it: the file was modified or corrupted")  # fmt: skip


def check_finite(path: Path, state: dict[str, torch.Tensor]) -> None:
    """Raise :class:`CheckpointError` naming the tensors holding NaN or infinite values."""
    bad = [k for k, v in state.items() if v.is_floating_point() and not torch.isfinite(v).all()]
    if bad:
        more = " ..." if len(bad) > 4 else ""
        raise CheckpointError(f"checkpoint {path} holds non-finite weights (NaN or inf) in "
                              f"{', '.join(bad[:4])}{more}: {RETRAIN}")  # fmt: skip


def seal(ckpt: dict[str, Any]) -> dict[str, Any]:
    """``ckpt`` with its record's digest recomputed (for tools and tests that edit a
    checkpoint on purpose; training seals every checkpoint it saves)."""
    record = {k: v for k, v in ckpt[RECORD_KEY].items() if k != DIGEST_KEY}
    record[DIGEST_KEY] = record_digest(record, ckpt["state_dict"])
    return {**ckpt, RECORD_KEY: record}


def require_target(record: dict, target: str, source: str, wanted_by: str = "asked for") -> None:
    """Raise :class:`CheckpointError` unless the network of ``source`` (its ``record``) was
    trained on ``target`` (``"vertex"`` or ``"path"``), naming both; ``wanted_by`` says who
    wants that target (``"--planner vnrrt_star samples"``)."""
    kind = (record.get("target") or {}).get("kind")
    if kind is None:
        raise CheckpointError(f"network {source} does not record its target: cannot check that "
                              f"it predicts the {target} heatmaps {wanted_by}")  # fmt: skip
    if kind != target:
        raise CheckpointError(f"network {source} predicts {kind} heatmaps, not the {target} "
                              f"heatmaps {wanted_by}")  # fmt: skip


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
    (a :class:`VertexNet` in eval mode, on CPU) and its record. ``network`` checks the
    record's network name; ``verify`` requires a ``.sha256`` file that matches
    (:func:`verify_checksum`)."""
    ckpt = read_checkpoint(path, verify)
    record = ckpt[RECORD_KEY]
    if network is not None and record["network"] != network:
        raise CheckpointError(f"checkpoint {path} holds {record['network']!r}, not {network!r}")
    net = VertexNet(**network_kwargs(Path(path), record["net"]), weights=None,
                    freeze_encoder=False)  # fmt: skip
    prefix = "net."
    state = {k[len(prefix) :]: v for k, v in ckpt["state_dict"].items() if k.startswith(prefix)}
    check_state_dict(Path(path), state, net)
    net.load_state_dict(state)
    return net.eval(), record
