"""Heatmap sources: what a learned planner samples, and how it is measured. A source is a
trained network (its predicted heatmap, read from the prediction files into
:attr:`EvalInstance.heatmaps`) or an oracle (:mod:`vnrrt.evaluation.oracles`, built from the
labels). Every source obeys one obstacle rule (:func:`allowed_cells`), applied here and in the
sampler's uniform part (:mod:`vnrrt.evaluation.sampling`).
"""

from __future__ import annotations

import math

import numpy as np

from vnrrt.data.heatmaps import HeatmapError
from vnrrt.evaluation.oracles import (  # noqa: F401  (re-exported: the sources' vocabulary)
    ORACLE_KINDS,
    TARGET,
    OracleSource,
    instance_heatmap,
    parse_source,
    source_name,
    target_mask,
)

ORACLE_PREFIX = "oracle_"


def is_oracle(source: str | None) -> bool:
    """Whether a heatmap source is an oracle (else a network, or None: uniform)."""
    return source is not None and source.startswith(ORACLE_PREFIX)


def mass_near(heatmap: np.ndarray, mask: np.ndarray, radius: float) -> float:
    """Share of ``heatmap``'s mass within ``radius`` px of a True cell of ``mask`` (the
    metric the networks report, :class:`vnrrt.model.metrics.MassNear`); NaN when the mask
    is empty or the heatmap has no mass."""
    from vnrrt.data.targets import dilate

    h = np.asarray(heatmap, np.float64)
    total = h.sum()
    if not mask.any() or total <= 0:
        return math.nan
    return float(h[dilate(mask, radius)].sum() / total)


def allowed_cells(grid: np.ndarray, zero_obstacles: bool) -> np.ndarray:
    """The obstacle rule, one for every heatmap source and for the uniform part of every
    sampler: ``(H, W)`` bool cells a sample may be drawn from, every cell (the paper's
    uniform sampling of the whole map) or, with ``zero_obstacles``, the free cells only."""
    occ = np.asarray(grid)
    return occ == 0 if zero_obstacles else np.ones(occ.shape, bool)


def source_heatmap(source: str, inst, sigma: float | None, floor: float | None,
                   allowed: np.ndarray) -> np.ndarray:  # fmt: skip
    """The heatmap a job samples, zero outside ``allowed`` (the obstacle rule): a network's
    (on the instance) or an oracle's (built with blur ``sigma`` px and uniform ``floor``,
    which an oracle needs), ``(H, W)`` float64."""
    if source in inst.heatmaps:
        return np.where(allowed, np.asarray(inst.heatmaps[source], np.float64), 0.0)
    if is_oracle(source):
        if floor is None:
            raise ValueError(f"oracle source {source!r} needs oracle.floor")
        return instance_heatmap(source, inst, sigma, floor, allowed).astype(np.float64)
    known = sorted(inst.heatmaps)
    raise HeatmapError(f"instance {inst.map} has no {source!r} heatmap (known: {known})")


def source_target(source: str, network_targets: dict[str, str]) -> str:
    """The target a source's heatmap aims at (for ``heat_mass``): an oracle's, or the
    network's (``network_targets``; ``'path'`` or ``'interior_vertices'``)."""
    if is_oracle(source):
        return TARGET[OracleSource.parse(source).kind]
    return network_targets.get(source, "path")


def mask_variant(heatmap: np.ndarray, variant: str, inst, endpoint_radius: float) -> np.ndarray:
    """``heatmap`` ``(H, W)`` prepared for M-VNRRT*'s mask variant
    (:data:`vnrrt.evaluation.keys.MASK_VARIANTS`): ``max`` divides it by its maximum (so tau
    reads as for the max-normalised oracles), ``noends`` zeroes the disks of
    ``endpoint_radius`` px around the start and goal cells; ``""`` leaves it."""
    h = np.asarray(heatmap, np.float64)
    if variant == "max":
        top = h.max()
        return h / top if top > 0 else h
    if variant == "noends":
        return np.where(endpoint_disks(inst, endpoint_radius), 0.0, h)
    if variant:
        raise ValueError(f"unknown mask variant {variant!r}")
    return h


def endpoint_disks(inst, radius: float) -> np.ndarray:
    """``(H, W)`` bool: the cells within ``radius`` px of the instance's start or goal cell."""
    from vnrrt.data.targets import dilate

    return dilate(target_mask(inst, "endpoints"), radius)


def mass_shares(weights: np.ndarray, inst, radius: float, endpoint_radius: float) -> dict:
    """Where a sampler's heatmap weights ``(H, W)`` lie, as shares of their total (NaN when
    they have none): ``mass_endpoints`` on the start/goal disks (``endpoint_radius``),
    ``mass_interior`` within ``radius`` px of the A* label's interior vertices (off those
    disks), ``mass_path`` within ``radius`` of the rest of the path (off both)."""
    from vnrrt.data.targets import dilate

    w = np.asarray(weights, np.float64)
    total = w.sum()
    if not total > 0:
        return {"mass_endpoints": math.nan, "mass_interior": math.nan, "mass_path": math.nan}
    ends = endpoint_disks(inst, endpoint_radius)
    interior = dilate(target_mask(inst, "interior_vertices"), radius) & ~ends
    path = dilate(target_mask(inst, "path"), radius) & ~ends & ~interior
    return {
        "mass_endpoints": float(w[ends].sum() / total),
        "mass_interior": float(w[interior].sum() / total),
        "mass_path": float(w[path].sum() / total),
    }
