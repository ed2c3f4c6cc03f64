"""One heatmap from a trained network for one (grid, start, goal), in one call.

A network comes from a vnrrt checkpoint (``models/<scale>/vertexnet.ckpt``), from an MLflow
model URI (``runs:/<run id>/vertexnet``, ``models:/vnrrt-vertexnet/1``, by the alias of the scale
that trained it: ``models:/vnrrt-vertexnet@quick``) or is given as a loaded
:class:`~vnrrt.predict.api.Model`. The input image is rendered exactly as in training (the
checkpoint's record: start/goal marker radius, normalisation). ``target`` asks for a network
trained on one target (``vnrrt.data.targets.PLANNER_TARGETS``: the one each planner samples);
a network of another target is refused. Every loading problem raises
:class:`~vnrrt.model.checkpoint.CheckpointError`.

An MLflow model is a pickle (``serialization_format="pickle"``): load models only from a
tracking store you trust. Checkpoint files are safe to load (:mod:`vnrrt.model.checkpoint`).
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


def _from_mlflow(uri: str, store: str) -> Model:
    """The model at ``uri`` (``runs:/``, or ``models:/<name>/<version>``) of tracking store
    ``store``."""
    import mlflow
    import mlflow.pytorch

    from vnrrt.model.checkpoint import CheckpointError

    mlflow.set_tracking_uri(store)
    try:
        net = mlflow.pytorch.load_model(uri, map_location="cpu")
        meta = mlflow.models.get_model_info(uri).metadata or {}
    except Exception as err:  # MlflowException, OSError, unpickling errors
        text = str(err).strip().splitlines()[0] if str(err).strip() else type(err).__name__
        raise CheckpointError(f"model {uri} cannot be loaded from {store}: {text}") from None
    if not isinstance(net, torch.nn.Module):  # a torch.export program (pt2 format)
        net = net.module()
    # the input rendering and target the network was trained with (logged as model metadata)
    record = {"render": dict(meta.get("render", DEFAULT_RENDER)), "source": uri}
    if "target" in meta:
        record["target"] = dict(meta["target"])
    return Model(net.eval(), record)


def _mlflow_source(uri: str) -> tuple[str, str]:
    """``(uri, store)``: an MLflow model URI with a registry alias resolved to the version it
    names now (``models:/vnrrt-vertexnet@quick`` -> ``models:/vnrrt-vertexnet/3``), and the
    tracking store it is read from; the two together name one model, so that a cache keyed by
    them never returns another store's version 1 or an alias's previous version."""
    from vnrrt.model.checkpoint import CheckpointError
    from vnrrt.tracking import store as tracking

    store = tracking.tracking_uri()
    tracking.check_store(store)
    name, at, alias = uri.removeprefix("models:/").partition("@")
    if not (uri.startswith("models:/") and at):
        return uri, store
    try:
        version = tracking.open_store(store).get_model_version_by_alias(name, alias).version
    except Exception as err:  # MlflowException: no such model or alias
        text = str(err).strip().splitlines()[0] if str(err).strip() else type(err).__name__
        raise CheckpointError(f"model {uri} cannot be loaded from {store}: {text}") from None
    return f"models:/{name}/{version}", store


@functools.lru_cache(maxsize=8)
def _cached(source: str, mtime: float, store: str | None = None) -> Model:
    if store is not None:
        return _from_mlflow(source, store)
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
        uri, store = _mlflow_source(text)
        model = _cached(uri, 0.0, store)
        return model if uri == text else Model(model.net, {**model.record, "source": text})
    path = Path(text)
    if not path.is_file():
        from vnrrt.model.checkpoint import CheckpointError

        raise CheckpointError(f"checkpoint {path} does not exist")
    return _cached(str(path.resolve()), path.stat().st_mtime)


ENCODER_STRIDE = 32  # VertexNet's encoder downsampling: stem, max-pool, layer2-4 (2**5)


def stride(net: torch.nn.Module) -> int:
    """The total downsampling of a network's encoder: its ``stride`` attribute where it has
    one, else :data:`ENCODER_STRIDE` (:class:`~vnrrt.model.vertexnet.VertexNet`'s)."""
    return int(getattr(net, "stride", ENCODER_STRIDE))


@torch.inference_mode()
def heatmap(
    model: str | Path | Model,
    grid: np.ndarray,
    start,
    goal,
    device: str | torch.device = "cpu",
    target: str | None = None,
    pad: bool = False,
) -> np.ndarray:
    """The network's probability of its positive class (vertex, or path cell) per pixel.

    Args:
        model: a checkpoint path, an MLflow model URI or a :class:`Model`.
        grid: ``(H, W)`` occupancy (nonzero = obstacle), indexed ``grid[y, x]``.
        start, goal: integer cells ``(x, y)`` in free space (the instance's endpoints).
        device: where to run the network (``"cpu"`` by default).
        target: ``"vertex"`` or ``"path"``: refuse a network trained on the other target
            (or recording none); ``PLANNER_TARGETS[planner]`` for a planner's heatmap
            (:mod:`vnrrt.data.targets`).
        pad: run the network on the map padded with obstacle rows and columns at the
            bottom and right to multiples of its encoder's stride (:func:`stride`, 32), then
            crop back: every feature level is aligned with the input at any map size (no
            shift). False (default): the map as it is, as the networks were trained.

    Returns:
        ``(H, W)`` float32 in [0, 1], indexed like ``grid``.
    """
    m = load_model(model)
    if target is not None:
        from vnrrt.model.checkpoint import require_target

        require_target(m.record, target, str(m.record.get("source") or model))
    occ = as_occupancy(grid)
    s, g = as_cell(occ, start, "start"), as_cell(occ, goal, "goal")
    h, w = occ.shape
    if pad:
        k = stride(m.net)
        occ = np.pad(occ, ((0, -h % k), (0, -w % k)), constant_values=1)
    image = render_instance(occ, s, g, **m.render)  # (3, H, W), padded when asked
    net = m.net.to(device)
    x = torch.from_numpy(image)[None].to(device)
    autocast = torch.autocast("cuda", torch.bfloat16) if x.device.type == "cuda" else None
    with autocast or contextlib.nullcontext():
        probs = net(x).float().softmax(dim=1)[0, 1]  # (H, W)
    out = probs[:h, :w].cpu().numpy().astype(np.float32)
    if not np.isfinite(out).all():
        raise ValueError(f"network {model} gave non-finite probabilities for this instance")
    return out
