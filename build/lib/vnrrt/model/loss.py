"""Focal loss (Lin et al. 2017) over 2-class logits, the paper's training objective."""

from __future__ import annotations

import torch
import torch.nn.functional as F
from torch import Tensor, nn

REDUCTIONS = ("mean", "sum", "none")


class FocalLoss(nn.Module):
    """FL(p_t) = -alpha_t (1 - p_t)^gamma log(p_t), with p_t the probability of the true class.

    Args:
        gamma: focusing parameter; 2 in the paper. ``gamma=0, alpha=None`` is cross-entropy.
        alpha: weight of class 1 (vertex); class 0 gets ``1 - alpha``. ``None``: no weighting
            (the paper's form, alpha_t = 1).
        reduction: ``"mean"`` over all pixels, ``"sum"``, or ``"none"`` for a (B, H, W) map.

    ``log p_t`` comes from ``log_softmax``, so large logits neither overflow nor give log(0).
    """

    def __init__(
        self, gamma: float = 2.0, alpha: float | None = None, reduction: str = "mean"
    ) -> None:
        super().__init__()
        if gamma < 0:
            raise ValueError(f"gamma must be >= 0, got {gamma}")
        if alpha is not None and not 0.0 <= alpha <= 1.0:
            raise ValueError(f"alpha must be in [0, 1] or None, got {alpha}")
        if reduction not in REDUCTIONS:
            raise ValueError(f"reduction must be one of {REDUCTIONS}, got {reduction!r}")
        self.gamma, self.alpha, self.reduction = gamma, alpha, reduction

    def forward(self, logits: Tensor, target: Tensor) -> Tensor:
        """logits: (B, 2, H, W) float; target: (B, H, W) integer in {0, 1} (1 = vertex).

        Returns a scalar (``mean``/``sum``) or the (B, H, W) per-pixel loss (``none``), float32
        even under mixed precision.
        """
        if logits.ndim != 4 or logits.shape[1] != 2 or target.shape != logits[:, 0].shape:
            raise ValueError(
                f"expected logits (B, 2, H, W) and target (B, H, W), "
                f"got {tuple(logits.shape)} and {tuple(target.shape)}"
            )
        target = target.long()
        log_p = F.log_softmax(logits.float(), dim=1)  # (B, 2, H, W)
        log_pt = log_p.gather(1, target.unsqueeze(1)).squeeze(1)  # (B, H, W)
        loss = -((1.0 - log_pt.exp()) ** self.gamma) * log_pt
        if self.alpha is not None:
            loss = torch.where(target == 1, self.alpha, 1.0 - self.alpha) * loss
        if self.reduction == "mean":
            return loss.mean()
        return loss.sum() if self.reduction == "sum" else loss
