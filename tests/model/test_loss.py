"""Focal loss against values worked out by hand from Lin et al.'s formula."""

import math

import pytest
import torch
import torch.nn.functional as F

from vnrrt.model import FocalLoss

# Two pixels: (background logit, vertex logit) and the true class.
LOGITS = [(2.0, -1.0, 1), (0.5, 0.0, 0)]


def softmax_p(logit0: float, logit1: float, cls: int) -> float:
    own, other = (logit1, logit0) if cls == 1 else (logit0, logit1)
    return 1.0 / (1.0 + math.exp(other - own))


def hand_focal(gamma: float, alpha: float | None) -> list[float]:
    losses = []
    for l0, l1, cls in LOGITS:
        p_t = softmax_p(l0, l1, cls)
        alpha_t = 1.0 if alpha is None else (alpha if cls == 1 else 1.0 - alpha)
        losses.append(-alpha_t * (1.0 - p_t) ** gamma * math.log(p_t))
    return losses


def as_tensors() -> tuple[torch.Tensor, torch.Tensor]:
    logits = torch.tensor([[l0, l1] for l0, l1, _ in LOGITS]).T.reshape(1, 2, 1, 2)
    target = torch.tensor([[[cls for *_, cls in LOGITS]]])  # (1, 1, 2)
    return logits, target


@pytest.mark.parametrize("alpha", [None, 0.25])
def test_matches_hand_computed_value(alpha: float | None) -> None:
    logits, target = as_tensors()
    expected = hand_focal(2.0, alpha)
    # Pixel 1: p_t = 1/(1+e^3) ~ 0.04743, (1-p_t)^2 ~ 0.90739, -log p_t ~ 3.04859 -> 2.76628;
    # pixel 2: p_t = 1/(1+e^-0.5) ~ 0.62246, (1-p_t)^2 ~ 0.14254, -log p_t ~ 0.47408 -> 0.06757.
    alpha_t = (1.0, 1.0) if alpha is None else (alpha, 1.0 - alpha)
    assert expected == pytest.approx([alpha_t[0] * 2.76628, alpha_t[1] * 0.06757], abs=1e-5)
    loss = FocalLoss(gamma=2.0, alpha=alpha)
    assert loss(logits, target).item() == pytest.approx(sum(expected) / 2, rel=1e-6)
    per_pixel = FocalLoss(gamma=2.0, alpha=alpha, reduction="none")(logits, target)
    assert per_pixel.shape == (1, 1, 2)
    assert per_pixel.flatten().tolist() == pytest.approx(expected, rel=1e-6)
    assert loss.__class__(2.0, alpha, "sum")(logits, target).item() == pytest.approx(sum(expected))


def test_gamma_zero_is_cross_entropy() -> None:
    torch.manual_seed(0)
    logits = torch.randn(2, 2, 9, 7) * 3
    target = torch.randint(0, 2, (2, 9, 7))
    focal = FocalLoss(gamma=0.0, alpha=None)(logits, target)
    assert focal.item() == pytest.approx(F.cross_entropy(logits, target).item(), rel=1e-6)


def test_easy_pixels_are_down_weighted_and_large_logits_stay_finite() -> None:
    logits = torch.tensor([[[[60.0, 0.0, -60.0]], [[-60.0, 0.0, 60.0]]]])  # (1, 2, 1, 3)
    target = torch.tensor([[[0, 0, 0]]])  # right, unsure, confidently wrong
    loss = FocalLoss(reduction="none")(logits, target)[0, 0]
    assert torch.isfinite(loss).all()
    assert loss[0].item() < 1e-30 and loss[2].item() == pytest.approx(120.0)
    assert loss[1].item() == pytest.approx(0.25 * math.log(2))


@pytest.mark.parametrize("kwargs", [{"gamma": -1.0}, {"alpha": 1.5}, {"reduction": "max"}])
def test_bad_arguments(kwargs: dict) -> None:
    with pytest.raises(ValueError):
        FocalLoss(**kwargs)


def test_bad_shapes() -> None:
    with pytest.raises(ValueError, match="expected logits"):
        FocalLoss()(torch.zeros(1, 3, 4, 4), torch.zeros(1, 4, 4, dtype=torch.long))
