"""VertexNet: the paper's parameter counts, output shapes, freezing policy and gradients."""

import pytest
import torch

from vnrrt.model import VertexNet

# Paper (VertexNet section): fastai unet_learner(resnet34, n_out=2) on 200x200 RGB images.
PAPER_TOTAL = 41_221_168
PAPER_TRAINABLE_FROZEN = 19_953_520


def n_params(model: torch.nn.Module, trainable: bool = False) -> int:
    return sum(p.numel() for p in model.parameters() if p.requires_grad or not trainable)


@pytest.fixture(scope="module")
def paper_net() -> VertexNet:
    torch.manual_seed(0)
    return VertexNet(encoder="resnet34", out_channels=2, weights=None).eval()


def test_paper_parameter_counts(paper_net: VertexNet) -> None:
    assert n_params(paper_net) == PAPER_TOTAL
    # "54 weighted layers": 36 encoder convs (3 of them 1x1 shortcuts) + 18 decoder convs.
    assert sum(isinstance(m, torch.nn.Conv2d) for m in paper_net.modules()) == 54
    paper_net.set_encoder_frozen(True)
    try:
        assert n_params(paper_net, trainable=True) == PAPER_TRAINABLE_FROZEN
        assert paper_net.describe()["params_trainable"] == PAPER_TRAINABLE_FROZEN
    finally:
        paper_net.set_encoder_frozen(False)
    assert n_params(paper_net, trainable=True) == PAPER_TOTAL


@pytest.mark.parametrize("size", [(200, 200), (97, 130), (32, 45)])
def test_forward_shape(paper_net: VertexNet, size: tuple[int, int]) -> None:
    with torch.no_grad():
        out = paper_net(torch.rand(1, 3, *size))
    assert out.shape == (1, 2, *size)
    assert out.dtype == torch.float32 and torch.isfinite(out).all()


def test_freezing_without_weights_trains_everything(caplog: pytest.LogCaptureFixture) -> None:
    net = VertexNet(encoder="resnet18", weights=None, freeze_encoder=True, decoder_width=0.25)
    assert net.encoder_frozen is False
    assert "freeze_encoder=True ignored" in caplog.text
    assert all(p.requires_grad for p in net.parameters())
    assert net.describe()["weights"] == "none"


def test_frozen_encoder_gets_no_weight_gradients() -> None:
    torch.manual_seed(0)
    net = VertexNet(encoder="resnet18", weights=None, freeze_encoder=False, decoder_width=0.25)
    net.set_encoder_frozen(True)
    net(torch.rand(2, 3, 64, 64)).logsumexp(1).mean().backward()
    assert net.encoder.conv1.weight.grad is None
    assert net.encoder.layer3[0].conv2.weight.grad is None
    assert net.encoder.bn1.weight.grad is not None  # BatchNorm stays trainable, as in fastai
    assert net.head.weight.grad is not None and net.middle[2][0].weight.grad is not None


def test_lite_variant_is_smaller_and_keeps_shapes() -> None:
    net = VertexNet(encoder="resnet18", decoder_width=0.5).eval()
    assert n_params(net) < PAPER_TOTAL / 2
    with torch.no_grad():
        assert net(torch.rand(2, 3, 97, 130)).shape == (2, 2, 97, 130)


def test_pixel_shuffle_starts_as_nearest_upsampling(paper_net: VertexNet) -> None:
    """ICNR init: the four sub-pixels of each upsampled channel are equal at initialisation."""
    shuf = paper_net.final_shuffle
    x = torch.rand(1, shuf[0].in_channels, 5, 7)
    with torch.no_grad():
        y = shuf(x)  # (1, C, 10, 14)
    assert torch.equal(y[..., 0::2, 0::2], y[..., 1::2, 1::2])
    assert torch.equal(y[..., 0::2, 1::2], y[..., 1::2, 0::2])


@pytest.mark.parametrize("shape", [(1, 1, 64, 64), (3, 64, 64), (1, 3, 16, 64)])
def test_bad_input_is_refused(paper_net: VertexNet, shape: tuple[int, ...]) -> None:
    with pytest.raises(ValueError, match="expected"):
        paper_net(torch.rand(*shape))
