"""The record a checkpoint carries beside its weights (the run's network config, target,
rendering) and the digest that binds the two; free of Lightning, so that loading a network
(:mod:`vnrrt.model.checkpoint`, the predict stages) does not import it."""

from __future__ import annotations

import hashlib
import json
from collections.abc import Mapping
from typing import Any

import torch
from torch import Tensor

RECORD_KEY = "vnrrt"  # checkpoint entry holding the run's record (network config, target, ...)
DIGEST_KEY = "sha256"  # record entry: sha256 of the rest of the record and of the state dict


def record_digest(record: Mapping[str, Any], state_dict: Mapping[str, Tensor]) -> str:
    """sha256 (hex) of a checkpoint's content: its record (canonical JSON, the
    :data:`DIGEST_KEY` entry left out) and every tensor of its state dict (name, dtype,
    shape and raw bytes, in name order). A changed weight or record value changes it."""
    h = hashlib.sha256()
    rest = {k: v for k, v in record.items() if k != DIGEST_KEY}
    h.update(json.dumps(rest, sort_keys=True, separators=(",", ":"), default=repr).encode())
    for name in sorted(state_dict):
        t = state_dict[name].detach().cpu().contiguous().reshape(-1)
        h.update(f"\0{name}\0{t.dtype}\0{tuple(state_dict[name].shape)}\0".encode())
        h.update(t.view(torch.uint8).numpy())  # the raw bytes, no copy
    return h.hexdigest()
