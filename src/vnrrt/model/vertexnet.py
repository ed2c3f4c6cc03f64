"""VertexNet: fastai's default ``unet_learner(dls, resnet34, n_out=2)`` U-Net in plain PyTorch.

fastai's ``DynamicUnet`` with its defaults (``blur=False, self_attention=False, y_range=None,
last_cross=True, bottle=False, act_cls=ReLU, norm_type=None``): the decoder convolutions carry
a bias and a ReLU but no BatchNorm; the only decoder BatchNorms are the one after the encoder and
one on each skip connection. For resnet34, 3 input and 2 output channels this gives the paper's
41,221,168 parameters, 19,953,520 of them trainable with the encoder frozen (its BatchNorms
excepted, as fastai's ``freeze`` leaves them trainable).

Data flow for a 200x200 input (channels, side):
encoder   stem (64,100) -> layer1 (64,50) -> layer2 (128,25) -> layer3 (256,13) -> layer4 (512,7)
middle    BN-ReLU, conv 512->1024, conv 1024->512                               -> (512,7)
blocks    shuffle-up, cat BN(skip), ReLU, two 3x3 convs: (512,13) (384,25) (256,50) (96,100)
final     shuffle-up (96,200), resize to the input, cat input (99,200), ResBlock, 1x1 conv (2,200)
"""

from __future__ import annotations

import logging
import math
from pathlib import Path

import torch
import torch.nn.functional as F
from torch import Tensor, nn

from vnrrt.model.resnet import ResNetEncoder, load_torchvision_weights, resolve_weights

log = logging.getLogger(__name__)


def conv_layer(ni: int, nf: int, ks: int = 3, act: bool = True) -> nn.Sequential:
    """fastai ``ConvLayer(ni, nf, ks, norm_type=None)``: conv (with bias) then ReLU if ``act``.

    Kaiming-normal weights and zero bias, as fastai's ``apply_init`` leaves them.
    """
    conv = nn.Conv2d(ni, nf, ks, padding=(ks - 1) // 2, bias=True)
    nn.init.kaiming_normal_(conv.weight)
    nn.init.zeros_(conv.bias)
    return nn.Sequential(conv, nn.ReLU(inplace=True)) if act else nn.Sequential(conv)


def batch_norm(nf: int) -> nn.BatchNorm2d:
    """fastai's ``BatchNorm``: weight 1, bias 1e-3."""
    bn = nn.BatchNorm2d(nf)
    nn.init.ones_(bn.weight)
    nn.init.constant_(bn.bias, 1e-3)
    return bn


@torch.no_grad()
def icnr_(weight: Tensor, scale: int = 2) -> Tensor:
    """ICNR init (Aitken et al. 2017) of a conv feeding ``PixelShuffle(scale)``, in place.

    weight: (C*scale^2, C_in, k, k). The scale^2 sub-pixel filters of each output channel are
    made equal, so the shuffled output starts as a nearest-neighbour upsampling.
    """
    sub = torch.empty(weight.shape[0] // scale**2, *weight.shape[1:], dtype=weight.dtype)
    nn.init.kaiming_normal_(sub)
    return weight.copy_(sub.repeat_interleave(scale**2, dim=0))


class PixelShuffleICNR(nn.Sequential):
    """fastai ``PixelShuffle_ICNR(ni, nf, norm_type=None)``: 1x1 conv, ReLU, PixelShuffle(2).

    (B, ni, H, W) -> (B, nf, 2H, 2W).
    """

    def __init__(self, ni: int, nf: int) -> None:
        conv = nn.Conv2d(ni, nf * 4, 1, bias=True)
        icnr_(conv.weight)
        nn.init.zeros_(conv.bias)
        super().__init__(conv, nn.ReLU(inplace=True), nn.PixelShuffle(2))


class UnetBlock(nn.Module):
    """fastai ``UnetBlock``: upsample, concatenate the BatchNorm'd skip, ReLU, two 3x3 convs.

    (B, up_in_c, h, w) and skip (B, x_in_c, H, W) with H ~ 2h -> (B, out_c, H, W).
    """

    def __init__(self, up_in_c: int, x_in_c: int, out_c: int) -> None:
        super().__init__()
        self.shuf = PixelShuffleICNR(up_in_c, up_in_c // 2)
        self.bn = batch_norm(x_in_c)
        self.conv1 = conv_layer(up_in_c // 2 + x_in_c, out_c)
        self.conv2 = conv_layer(out_c, out_c)

    def forward(self, up_in: Tensor, skip: Tensor) -> Tensor:
        up = self.shuf(up_in)  # (B, up_in_c/2, 2h, 2w)
        if up.shape[-2:] != skip.shape[-2:]:  # odd sizes: 2h = H + 1
            up = F.interpolate(up, skip.shape[-2:], mode="nearest")
        cat = F.relu(torch.cat([up, self.bn(skip)], dim=1))  # (B, up_in_c/2 + x_in_c, H, W)
        return self.conv2(self.conv1(cat))


class ResBlock(nn.Module):
    """fastai ``ResBlock(1, nf, nf, norm_type=None)``: ReLU(x + conv(ReLU(conv(x)))).

    (B, nf, H, W) -> (B, nf, H, W).
    """

    def __init__(self, nf: int) -> None:
        super().__init__()
        self.convpath = nn.Sequential(conv_layer(nf, nf), conv_layer(nf, nf, act=False))

    def forward(self, x: Tensor) -> Tensor:
        return F.relu(self.convpath(x) + x)


class VertexNet(nn.Module):
    """U-Net over a ResNet encoder predicting per-pixel class logits (the paper's VertexNet).

    Args:
        encoder: ``"resnet34"`` (paper) or ``"resnet18"`` (lighter).
        out_channels: logit channels; 2 (background, vertex) in the paper.
        weights: encoder weights: ``None``/``"none"`` (random init), ``"imagenet"`` (torchvision's
            file in the torch hub cache, never downloaded here) or a path to a torchvision-format
            ResNet ``state_dict``. Missing files and mismatched keys raise a clear error.
        freeze_encoder: freeze the encoder except its BatchNorm layers (fastai's ``freeze``).
            Only meaningful over loaded weights: with ``weights=None`` freezing is turned off
            with a logged warning and the whole network trains. ``encoder_frozen`` records the
            outcome; :meth:`set_encoder_frozen` changes it later (e.g. to unfreeze).
        in_channels: input image channels.
        decoder_width: factor on every decoder convolution's width; 1.0 is fastai's decoder,
            smaller values give a cheaper network for CPU runs.
        encoder_width: factor on the encoder's channel counts (:class:`ResNetEncoder`); 1.0
            (the paper, and the only width torchvision weight files fit) or less for CPU runs.
        prior: if set, the head's biases start so that every pixel's class-1 probability is
            ``prior`` (Lin et al. 2017's init for focal loss: training does not first spend
            steps learning that almost every pixel is background). None: fastai's init.
    """

    def __init__(
        self,
        encoder: str = "resnet34",
        out_channels: int = 2,
        weights: str | Path | None = None,
        freeze_encoder: bool = True,
        in_channels: int = 3,
        decoder_width: float = 1.0,
        encoder_width: float = 1.0,
        prior: float | None = None,
    ) -> None:
        super().__init__()
        if decoder_width <= 0:
            raise ValueError(f"decoder_width must be positive, got {decoder_width}")
        self.in_channels, self.out_channels = in_channels, out_channels
        self.decoder_width = decoder_width
        self.encoder = ResNetEncoder(encoder, in_channels, encoder_width)
        self._build_decoder(out_channels)
        if prior is not None:
            self._init_prior(prior)
        self.weights_path = resolve_weights(weights, encoder)
        if self.weights_path is not None:
            load_torchvision_weights(self.encoder, self.weights_path)
        if freeze_encoder and self.weights_path is None:
            log.warning("freeze_encoder=True ignored: no encoder weights; training all layers")
            freeze_encoder = False
        self.encoder_frozen = False
        self.set_encoder_frozen(freeze_encoder)

    def _width(self, channels: int) -> int:
        return max(1, round(channels * self.decoder_width))

    def _build_decoder(self, out_channels: int) -> None:
        """Create middle, UNet blocks, final upsampling, residual block and head, as fastai does."""
        *skips, ni = self.encoder.channels  # skips (64, 64, 128, 256), ni = 512 (width 1)
        mid = self._width(ni)
        self.middle = nn.Sequential(
            batch_norm(ni),
            nn.ReLU(),
            conv_layer(ni, self._width(2 * ni)),
            conv_layer(self._width(2 * ni), mid),
        )
        blocks, up_c = [], mid
        for i, x_c in enumerate(reversed(skips)):
            final = i == len(skips) - 1
            cat_c = up_c // 2 + x_c
            out_c = max(1, self._width(cat_c) // 2) if final else self._width(cat_c)
            blocks.append(UnetBlock(up_c, x_c, out_c))
            up_c = out_c
        self.blocks = nn.ModuleList(blocks)
        self.final_shuffle = PixelShuffleICNR(up_c, up_c)
        self.res_block = ResBlock(up_c + self.in_channels)
        self.head = nn.Conv2d(up_c + self.in_channels, out_channels, 1)  # PyTorch default init
        nn.init.normal_(self.head.bias, 0.0, 0.01)

    @torch.no_grad()
    def _init_prior(self, prior: float) -> None:
        """Biases 0 for class 0 and ``log(prior / (1 - prior))`` for the others."""
        if not 0.0 < prior < 1.0:
            raise ValueError(f"prior must be in (0, 1), got {prior}")
        self.head.bias.zero_()
        self.head.bias[1:] = math.log(prior / (1.0 - prior))

    def set_encoder_frozen(self, frozen: bool = True) -> None:
        """Freeze (or unfreeze) the encoder's weights; its BatchNorm parameters stay trainable.

        Frozen BatchNorms still update their running statistics in train mode, as in fastai.
        """
        for module in self.encoder.modules():
            trainable = not frozen or isinstance(module, nn.BatchNorm2d)
            for p in module.parameters(recurse=False):
                p.requires_grad_(trainable)
        self.encoder_frozen = frozen

    def describe(self) -> dict[str, str | int | float | bool]:
        """What a run should record: encoder, weights file, freezing and parameter counts."""
        return {
            "encoder": self.encoder.name,
            "weights": str(self.weights_path) if self.weights_path else "none",
            "encoder_frozen": self.encoder_frozen,
            "decoder_width": self.decoder_width,
            "encoder_width": self.encoder.width,
            "params_total": sum(p.numel() for p in self.parameters()),
            "params_trainable": sum(p.numel() for p in self.parameters() if p.requires_grad),
        }

    def forward(self, x: Tensor) -> Tensor:
        """x: (B, in_channels, H, W) float image, H, W >= 32 -> (B, out_channels, H, W) logits.

        The image is used as the encoder was trained (ImageNet-normalised for ImageNet weights);
        class probabilities are ``logits.softmax(dim=1)``.
        """
        if x.ndim != 4 or x.shape[1] != self.in_channels or min(x.shape[-2:]) < 32:
            raise ValueError(
                f"expected (B, {self.in_channels}, H>=32, W>=32), got {tuple(x.shape)}"
            )
        *skips, y = self.encoder(x)  # skips finest first; y: (B, 512, H/32, W/32)
        y = self.middle(y)
        for block, skip in zip(self.blocks, reversed(skips), strict=True):
            y = block(y, skip)  # ends at (B, C, H/2, W/2)
        y = self.final_shuffle(y)  # (B, C, ~H, ~W)
        if y.shape[-2:] != x.shape[-2:]:
            y = F.interpolate(y, x.shape[-2:], mode="nearest")
        y = self.res_block(torch.cat([y, x], dim=1))  # (B, C + in_channels, H, W)
        return self.head(y)
