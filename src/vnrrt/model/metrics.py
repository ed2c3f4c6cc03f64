"""Heatmap metrics (torchmetrics) of a predicted probability map ``preds`` ``(B, H, W)`` in
[0, 1] (the positive class: vertex, or path cell for the NRRT* network).

* :class:`VertexRecall`: share of true vertices with a pixel of probability >= ``tau`` within
  ``radius`` pixels (over all vertices of all images).
* :class:`MaskedAveragePrecision`: pixel AP against a label mask, some pixels ignored.
* :class:`MassNear`: share of an image's predicted probability mass within ``radius`` pixels
  of a mask (the optimal path or its vertices), averaged over images. That is the chance that
  the heatmap sampler of VertexNet RRT* draws a pixel near the mask; ``uniform=True`` gives the
  same share for a uniform heatmap (the area fraction of the dilated mask), the baseline.

"Within r pixels" is the disk of :func:`vnrrt.grid.disk`, as for the target dilation.
:func:`metric_collection` builds the set logged per split with pixel AP and F1 at 0.5.
"""

from __future__ import annotations

import torch
import torch.nn.functional as F
from torch import Tensor
from torchmetrics import Metric, MetricCollection
from torchmetrics.classification import BinaryF1Score

from vnrrt.grid import disk

LABEL_MASKS = ("vertices", "path", "interior", "endpoints")  # vnrrt.data.targets.label_masks


def dilate(mask: Tensor, radius: float) -> Tensor:
    """``(B, H, W)`` bool: pixels within ``radius`` of a True pixel of ``mask`` ``(B, H, W)``."""
    if radius < 1:
        return mask.bool()
    kernel = torch.as_tensor(disk(radius), dtype=torch.float32, device=mask.device)
    k = kernel.shape[-1] // 2
    hits = F.conv2d(mask.float().unsqueeze(1), kernel[None, None], padding=k)  # (B, 1, H, W)
    return hits.squeeze(1) > 0.5


class PixelAveragePrecision(Metric):
    """Average precision of ``preds`` ``(B, H, W)`` against a binary ``target`` ``(B, H, W)``
    over all pixels, on ``thresholds`` evenly spaced thresholds in [0, 1] (fixed memory).

    The same value as torchmetrics' ``BinaryAveragePrecision(thresholds=T)``: a pixel is
    positive at threshold ``t_j = j / (T - 1)`` when ``pred >= t_j``, and AP is the sum over
    thresholds of (recall drop) x precision. Counts come from one ``torch.bincount`` of the
    threshold bins, so the cost is O(pixels), also in deterministic mode (where torchmetrics
    falls back to an O(pixels x 4T) comparison that needs gigabytes for a batch of maps).
    """

    higher_is_better = True
    full_state_update = False

    def __init__(self, thresholds: int = 101, **kwargs) -> None:
        super().__init__(**kwargs)
        if thresholds < 2:
            raise ValueError(f"need at least 2 thresholds, got {thresholds}")
        self.thresholds = thresholds
        self.add_state("hist", torch.zeros(2, thresholds, dtype=torch.int64), dist_reduce_fx="sum")

    def update(self, preds: Tensor, target: Tensor) -> None:
        t = self.thresholds
        bins = (preds.detach().flatten().float().clamp(0, 1) * (t - 1)).floor().long()  # (N,)
        # Bin j holds preds in [t_j, t_j+1); floor may miss a pred that equals t_j+1 in float.
        bins = torch.where(preds.flatten() >= (bins + 1) / (t - 1), bins + 1, bins).clamp(max=t - 1)
        key = bins + t * (target.flatten() == 1).long()  # negatives 0..T-1, positives T..2T-1
        self.hist += torch.bincount(key, minlength=2 * t).view(2, t)

    def compute(self) -> Tensor:
        # TP(j), FP(j): pixels with pred >= t_j = reverse cumulative sums of the histograms.
        fp, tp = self.hist.flip(-1).cumsum(-1).flip(-1).double()  # (T,) each
        precision = torch.where(tp + fp > 0, tp / (tp + fp).clamp_min(1), 1.0)
        recall = tp / tp[0].clamp_min(1)
        drop = recall - torch.cat([recall[1:], recall.new_zeros(1)])  # R(j) - R(j+1)
        return (drop * precision).sum().float()


class VertexRecall(Metric):
    """Share of true vertices (``vertices`` ``(B, H, W)`` bool) within ``radius`` pixels of a
    pixel whose predicted probability is >= ``tau``; 0 when there are no vertices."""

    higher_is_better = True
    full_state_update = False

    def __init__(self, radius: float = 3.0, tau: float = 0.5, mask: str = "vertices",
                 **kwargs) -> None:  # fmt: skip
        super().__init__(**kwargs)
        self.radius, self.tau, self.mask = radius, tau, mask
        self.add_state("hits", torch.tensor(0.0), dist_reduce_fx="sum")
        self.add_state("total", torch.tensor(0.0), dist_reduce_fx="sum")

    def update(self, preds: Tensor, **masks: Tensor) -> None:
        near = dilate(preds >= self.tau, self.radius)  # (B, H, W)
        vertices = masks[self.mask].bool()
        self.hits += (near & vertices).sum()
        self.total += vertices.sum()

    def compute(self) -> Tensor:
        return self.hits / self.total.clamp_min(1.0)


class MassNear(Metric):
    """Mean over images of the share of predicted mass within ``radius`` pixels of a mask.

    ``mask`` names the keyword the mask arrives under in :meth:`update` (``"path"`` or
    ``"vertices"``, both ``(B, H, W)`` bool). ``uniform=True`` ignores ``preds`` and reports
    the share a uniform heatmap would have (the dilated mask's area fraction). ``tau`` zeroes
    probabilities below it first (the M-VNRRT* sampler); an image left without mass counts
    as uniform, as that sampler then falls back to uniform sampling.
    """

    higher_is_better = True
    full_state_update = False

    def __init__(self, radius: float = 3.0, mask: str = "path", uniform: bool = False,
                 tau: float | None = None, **kw) -> None:  # fmt: skip
        super().__init__(**kw)
        self.radius, self.mask, self.uniform, self.tau = radius, mask, uniform, tau
        self.add_state("share_sum", torch.tensor(0.0, dtype=torch.float64), dist_reduce_fx="sum")
        self.add_state("images", torch.tensor(0.0, dtype=torch.float64), dist_reduce_fx="sum")

    def update(self, preds: Tensor, **masks: Tensor) -> None:
        near = dilate(masks[self.mask], self.radius).flatten(1)  # (B, H*W)
        area = near.double().mean(1)  # (B,) the uniform share
        p = preds.flatten(1).double()  # (B, H*W)
        if self.tau is not None:
            p = torch.where(p >= self.tau, p, 0.0)
        total = p.sum(1)
        share = (p * near).sum(1) / total.clamp_min(1e-12)
        if self.uniform:
            share = area
        elif self.tau is not None:
            share = torch.where(total > 0, share, area)
        self.share_sum += share.sum()
        self.images += share.numel()

    def compute(self) -> Tensor:
        return (self.share_sum / self.images.clamp_min(1.0)).float()


class MaskedAveragePrecision(PixelAveragePrecision):
    """Pixel AP of ``preds`` against positives ``mask`` dilated by ``radius`` px, with the
    pixels of ``ignore`` (dilated by ``ignore_radius``) left out of the count: the interior
    vertices' AP ignores the start and goal disks, which a vertex target marks too."""

    def __init__(self, mask: str, radius: float = 1.0, ignore: str | None = None,
                 ignore_radius: float = 0.0, thresholds: int = 101, **kw) -> None:  # fmt: skip
        super().__init__(thresholds, **kw)
        self.mask, self.radius = mask, radius
        self.ignore, self.ignore_radius = ignore, ignore_radius

    def update(self, preds: Tensor, **masks: Tensor) -> None:  # type: ignore[override]
        target = dilate(masks[self.mask], self.radius)
        keep = torch.ones_like(target)
        if self.ignore is not None:
            keep = ~dilate(masks[self.ignore], self.ignore_radius) | target
        super().update(preds[keep], target[keep].long())


def tau_key(name: str, tau: float) -> str:
    """``name`` for the heatmap masked below ``tau``: ``mass_near_interior_tau0_9``."""
    return f"{name}_tau{tau:g}".replace(".", "_")


def heatmap_metric_set(radius: float, tau: float, ap_radius: float, endpoint_radius: float,
                       taus=()) -> dict[str, Metric]:  # fmt: skip
    """The heatmap metrics, updated with ``update(preds=, vertices=, path=, interior=,
    endpoints=)`` (``(B, H, W)`` bool masks; ``interior``: vertices without start and goal):

    * ``vertex_recall`` / ``interior_recall``: vertices (all, interior) with a pixel of
      probability >= ``tau`` within ``radius`` px;
    * ``interior_ap``: pixel AP against the interior vertices (dilated by ``ap_radius`` px),
      the start and goal disks (``endpoint_radius``) ignored; ``path_ap``: against the path
      (dilated by ``ap_radius`` px), the same rule for the path network;
    * ``mass_near_<mask>`` and ``..._uniform``: the share of the heatmap's mass within
      ``radius`` px of the path, all vertices, the interior vertices, and a uniform map's;
    * ``mass_on_endpoints``: the share within ``endpoint_radius`` of start and goal;
    * ``mass_near_interior_tau<t>`` (``tau0_9`` for 0.9): the interior share after masking
      below each ``t`` of ``taus`` (M-VNRRT*'s sampler; an image left empty counts as
      uniform).
    """
    metrics = {
        "vertex_recall": VertexRecall(radius, tau),
        "interior_recall": VertexRecall(radius, tau, mask="interior"),
        "interior_ap": MaskedAveragePrecision("interior", ap_radius, "endpoints", endpoint_radius),
        "path_ap": MaskedAveragePrecision("path", ap_radius),
        "mass_near_path": MassNear(radius, "path"),
        "mass_near_path_uniform": MassNear(radius, "path", uniform=True),
        "mass_near_vertex": MassNear(radius, "vertices"),
        "mass_near_vertex_uniform": MassNear(radius, "vertices", uniform=True),
        "mass_near_vertex_masked": MassNear(radius, "vertices", tau=tau),
        "mass_near_interior": MassNear(radius, "interior"),
        "mass_near_interior_uniform": MassNear(radius, "interior", uniform=True),
        "mass_on_endpoints": MassNear(endpoint_radius, "endpoints"),
    }
    for t in taus:
        metrics[tau_key("mass_near_interior", t)] = MassNear(radius, "interior", tau=t)
    return metrics


def metric_collection(radius: float, tau: float, ap_radius: float, endpoint_radius: float,
                      taus=(), ap_thresholds: int = 101,
                      with_target: bool = True) -> MetricCollection:  # fmt: skip
    """The metrics of one split, updated with ``update(preds=, target=, vertices=, path=,
    interior=, endpoints=)``: pixel ``ap`` (binned over ``ap_thresholds``) and ``f1`` (at 0.5)
    against the training target (unless ``with_target`` is False), and
    :func:`heatmap_metric_set` (its arguments)."""
    metrics = heatmap_metric_set(radius, tau, ap_radius, endpoint_radius, taus)
    if with_target:
        metrics["ap"] = PixelAveragePrecision(ap_thresholds)
        metrics["f1"] = BinaryF1Score(threshold=0.5, validate_args=False)
    return MetricCollection(metrics, compute_groups=False)  # equal states must not merge
