"""ResNet18/34 encoder with torchvision-compatible parameter names.

torchvision cannot be imported beside the pinned torch, so the encoder is written here. Its
``state_dict`` keys and shapes are exactly those of ``torchvision.models.resnet18/34`` minus the
classification head (``fc.*``), so torchvision's ImageNet files (``resnet34-b627a593.pth``)
load with strict name and shape checking through :func:`load_torchvision_weights`.
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path

import torch
from torch import Tensor, nn

# Basic blocks per stage (He et al. 2016, table 1).
LAYERS: dict[str, tuple[int, int, int, int]] = {
    "resnet18": (2, 2, 2, 2),
    "resnet34": (3, 4, 6, 3),
}
# torchvision's IMAGENET1K_V1 files, as named in the torch hub cache (``<hub>/checkpoints/``).
IMAGENET_FILES: dict[str, str] = {
    "resnet18": "resnet18-f37072fd.pth",
    "resnet34": "resnet34-b627a593.pth",
}
IMAGENET_URL = "https://download.pytorch.org/models/{}"
# Keys of torchvision's classification head, present in its files and absent from the encoder.
HEAD_KEYS = ("fc.weight", "fc.bias")


class BasicBlock(nn.Module):
    """Two 3x3 convolutions with an identity (or 1x1 projection) shortcut; torchvision names.

    (B, in_planes, H, W) -> (B, planes, ceil(H/stride), ceil(W/stride)).
    """

    def __init__(self, in_planes: int, planes: int, stride: int = 1) -> None:
        super().__init__()
        self.conv1 = nn.Conv2d(in_planes, planes, 3, stride, 1, bias=False)
        self.bn1 = nn.BatchNorm2d(planes)
        self.relu = nn.ReLU(inplace=True)
        self.conv2 = nn.Conv2d(planes, planes, 3, 1, 1, bias=False)
        self.bn2 = nn.BatchNorm2d(planes)
        self.downsample: nn.Module | None = None
        if stride != 1 or in_planes != planes:
            self.downsample = nn.Sequential(
                nn.Conv2d(in_planes, planes, 1, stride, bias=False), nn.BatchNorm2d(planes)
            )

    def forward(self, x: Tensor) -> Tensor:
        identity = x if self.downsample is None else self.downsample(x)
        out = self.relu(self.bn1(self.conv1(x)))
        out = self.bn2(self.conv2(out))
        return self.relu(out + identity)


class ResNetEncoder(nn.Module):
    """The ResNet body (stem + 4 stages, no pooling head) returning the U-Net skip features.

    Attributes ``conv1, bn1, relu, maxpool, layer1..layer4`` carry torchvision's names.
    ``channels`` lists the channel counts of the returned features, ``layer_counts`` the
    number of basic blocks per stage. ``width`` scales every channel count (1.0: torchvision's
    ResNet, the only width its weight files fit; 0.5: a 4x cheaper encoder for CPU runs).
    """

    def __init__(self, name: str = "resnet34", in_channels: int = 3, width: float = 1.0) -> None:
        super().__init__()
        if name not in LAYERS:
            raise ValueError(f"unknown encoder {name!r}; expected one of {sorted(LAYERS)}")
        if width <= 0:
            raise ValueError(f"encoder width must be positive, got {width}")
        self.name, self.width = name, width
        self.layer_counts = LAYERS[name]
        stem, *widths = (max(8, round(c * width)) for c in (64, 64, 128, 256, 512))
        self.conv1 = nn.Conv2d(in_channels, stem, 7, 2, 3, bias=False)
        self.bn1 = nn.BatchNorm2d(stem)
        self.relu = nn.ReLU(inplace=True)
        self.maxpool = nn.MaxPool2d(3, 2, 1)
        in_planes = stem
        for i, (planes, blocks) in enumerate(zip(widths, LAYERS[name], strict=True)):
            stride = 1 if i == 0 else 2
            stage = [BasicBlock(in_planes, planes, stride)]
            stage += [BasicBlock(planes, planes) for _ in range(blocks - 1)]
            self.add_module(f"layer{i + 1}", nn.Sequential(*stage))
            in_planes = planes
        self.channels = (stem, *widths)
        self._init_weights()

    def _init_weights(self) -> None:
        """torchvision's random initialisation (kaiming-normal fan_out convs, BN = identity)."""
        for m in self.modules():
            if isinstance(m, nn.Conv2d):
                nn.init.kaiming_normal_(m.weight, mode="fan_out", nonlinearity="relu")
            elif isinstance(m, nn.BatchNorm2d):
                nn.init.ones_(m.weight)
                nn.init.zeros_(m.bias)

    def forward(self, x: Tensor) -> list[Tensor]:
        """x: (B, C, H, W) -> features where the resolution changes, finest first.

        Returns [stem (B,64,H/2), layer1 (B,64,H/4), layer2 (B,128,H/8), layer3 (B,256,H/16),
        layer4 (B,512,H/32)] (sizes rounded up, as the strided convolutions do; channels times
        ``width``).
        """
        stem = self.relu(self.bn1(self.conv1(x)))  # (B, 64, H/2, W/2)
        f1 = self.layer1(self.maxpool(stem))  # (B, 64, H/4, W/4)
        f2 = self.layer2(f1)  # (B, 128, H/8, W/8)
        f3 = self.layer3(f2)  # (B, 256, H/16, W/16)
        f4 = self.layer4(f3)  # (B, 512, H/32, W/32)
        return [stem, f1, f2, f3, f4]


def imagenet_weights_path(name: str) -> Path:
    """Where torchvision keeps the ImageNet file of encoder ``name``: ``<hub dir>/checkpoints/``."""
    return Path(torch.hub.get_dir()) / "checkpoints" / IMAGENET_FILES[name]


def _describe(keys: list[str], limit: int = 8) -> str:
    shown = ", ".join(keys[:limit])
    return shown + (f", ... ({len(keys)} in all)" if len(keys) > limit else "")


def check_state_dict(encoder: nn.Module, state: Mapping[str, Tensor], source: str) -> None:
    """Raise ``ValueError`` naming every missing, unexpected or shape-mismatched key.

    ``num_batches_tracked`` buffers may be absent (older torchvision files omit them).
    """
    expected = {k: v.shape for k, v in encoder.state_dict().items()}
    missing = [k for k in expected if k not in state and not k.endswith("num_batches_tracked")]
    unexpected = [k for k in state if k not in expected]
    mismatched = [
        f"{k}: file {tuple(state[k].shape)} vs model {tuple(expected[k])}"
        for k in expected
        if k in state and tuple(state[k].shape) != tuple(expected[k])
    ]
    problems = [
        f"{label} ({len(keys)}): {_describe(keys)}"
        for label, keys in (
            ("missing keys", missing),
            ("unexpected keys", unexpected),
            ("shape mismatches", mismatched),
        )
        if keys
    ]
    if problems:
        raise ValueError(
            f"{source} is not a torchvision {getattr(encoder, 'name', 'resnet')} state_dict: "
            + "; ".join(problems)
        )


def load_torchvision_weights(encoder: ResNetEncoder, path: str | Path) -> None:
    """Load a torchvision-format ResNet ``state_dict`` file into ``encoder`` (strict names).

    The classification head (``fc.weight``, ``fc.bias``) is dropped if present; every other key
    must match the encoder's names and shapes exactly, else ``ValueError`` lists the differences.
    Raises ``FileNotFoundError`` when ``path`` does not exist.
    """
    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"encoder weights file not found: {path}")
    state = torch.load(path, map_location="cpu", weights_only=True)
    if not isinstance(state, Mapping) or not all(isinstance(v, Tensor) for v in state.values()):
        raise ValueError(f"{path} does not hold a state_dict (a mapping of names to tensors)")
    state = {k: v for k, v in state.items() if k not in HEAD_KEYS}
    check_state_dict(encoder, state, str(path))
    encoder.load_state_dict(state, strict=False)  # strictness checked above


def resolve_weights(weights: str | Path | None, name: str) -> Path | None:
    """Map the ``weights`` setting to a file: ``None``/``"none"`` -> None (random init),
    ``"imagenet"`` -> torchvision's file in the torch hub cache, anything else -> that path.

    Raises ``FileNotFoundError`` (saying how to obtain it) when the ImageNet file is absent:
    nothing is downloaded here.
    """
    if weights is None or str(weights).lower() == "none":
        return None
    if str(weights).lower() != "imagenet":
        return Path(weights)
    path = imagenet_weights_path(name)
    if not path.is_file():
        url = IMAGENET_URL.format(IMAGENET_FILES[name])
        raise FileNotFoundError(
            f"ImageNet weights for {name} not found at {path}. This machine cannot download "
            f"them: fetch {url} elsewhere and copy it to {path}, or pass its path as weights."
        )
    return path
