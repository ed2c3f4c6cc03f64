"""One heatmap from a trained network for one (grid, start, goal), in one call.

A network comes from a vnrrt checkpoint (``models/<scale>/vertexnet.ckpt``), from an MLflow
model URI (``runs:/<run id>/model``, ``models:/vnrrt-vertexnet/1``) or is given as a loaded
:class:`~vnrrt.predict.api.Model`. The input image is rendered exactly as in training (the
checkpoint's record: start/goal marker radius, normalisation).
"""

from __future__ import annotations

import contextlib
import functools
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import torch

from vnrrt.grid import as_cell, as_occupancy
from vnrrt.maps.render import render_instance

DEFAULT_RENDER = {"marker_radius": 2.0, "normalize": "imagenet"}


@dataclass(frozen=True)
class Model:
    """A network ``(B, 3, H, W) -> (B, 2, H, W)`` logits in eval mode, with its record
    (target kind and radius, input rendering; see :mod:`vnrrt.model.checkpoint`)."""

    net: torch.nn.Module
    record: dict

    @property
    def render(self) -> dict:
        return self.record.get("render", DEFAULT_RENDER)


def _from_mlflow(uri: str) -> Model:
    try:
        import mlflow.pytorch
    except ImportError as err:  # pragma: no cover - mlflow is a dependency of the pipeline
        raise ValueError(f"loading {uri!r} needs mlflow installed") from err
    import mlflow

    from vnrrt import tracking

    mlflow.set_tracking_uri(tracking.tracking_uri())
    net = mlflow.pytorch.load_model(uri, map_location="cpu")
    if not isinstance(net, torch.nn.Module):  # a torch.export program (pt2 format)
        net = net.module()
    # the input rendering the network was trained with (logged as model metadata)
    render = (mlflow.models.get_model_info(uri).metadata or {}).get("render", DEFAULT_RENDER)
    return Model(net.eval(), {"render": dict(render), "source": uri})


@functools.lru_cache(maxsize=8)
def _cached(source: str, mtime: float) -> Model:
    if source.startswith(("runs:/", "models:/")):
        return _from_mlflow(source)
    from vnrrt.model.checkpoint import load_network

    net, record = load_network(source)
    return Model(net, record)


def load_model(source: str | Path | Model) -> Model:
    """A :class:`Model` from a checkpoint path, an MLflow model URI or a loaded model
    (cached per file and modification time)."""
    if isinstance(source, Model):
        return source
    text = str(source)
    if text.startswith(("runs:/", "models:/")):
        return _cached(text, 0.0)
    path = Path(text)
    if not path.is_file():
        from vnrrt.model.checkpoint import CheckpointError

        raise CheckpointError(f"checkpoint {path} does not exist")
    return _cached(str(path.resolve()), path.stat().st_mtime)


@torch.inference_mode()
def heatmap(
    model: str | Path | Model, grid: np.ndarray, start, goal, device: str | torch.device = "cpu"
) -> np.ndarray:
    """The network's probability of its positive class (vertex, or path cell) per pixel.

    Args:
        model: a checkpoint path, an MLflow model URI or a :class:`Model`.
        grid: ``(H, W)`` occupancy (nonzero = obstacle), indexed ``grid[y, x]``.
        start, goal: integer cells ``(x, y)`` in free space (the instance's endpoints).
        device: where to run the network (``"cpu"`` by default).

    Returns:
        ``(H, W)`` float32 in [0, 1], indexed like ``grid``.
    """
    m = load_model(model)
    occ = as_occupancy(grid)
    s, g = as_cell(occ, start, "start"), as_cell(occ, goal, "goal")
    image = render_instance(occ, s, g, **m.render)  # (3, H, W)
    net = m.net.to(device)
    x = torch.from_numpy(image)[None].to(device)
    autocast = torch.autocast("cuda", torch.bfloat16) if x.device.type == "cuda" else None
    with autocast or contextlib.nullcontext():
        probs = net(x).float().softmax(dim=1)[0, 1]  # (H, W)
    return probs.cpu().numpy().astype(np.float32)
