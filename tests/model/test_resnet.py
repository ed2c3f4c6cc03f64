"""Encoder: torchvision-compatible names, strict loading of weight files and clear errors."""

from pathlib import Path

import pytest
import torch

from vnrrt.model import ResNetEncoder, VertexNet, load_torchvision_weights
from vnrrt.model.resnet import IMAGENET_FILES

# torchvision's published sizes (weights docs): parameters including the 512 -> 1000 fc head.
TORCHVISION_PARAMS = {"resnet18": 11_689_512, "resnet34": 21_797_672}
FC_PARAMS = 512 * 1000 + 1000


def torchvision_file(encoder: ResNetEncoder, path: Path) -> Path:
    """Write ``encoder``'s weights as torchvision does: flat state_dict plus the fc head."""
    state = dict(encoder.state_dict())
    state["fc.weight"], state["fc.bias"] = torch.randn(1000, 512), torch.randn(1000)
    torch.save(state, path)
    return path


@pytest.mark.parametrize("name", ["resnet18", "resnet34"])
def test_names_and_sizes_match_torchvision(name: str) -> None:
    encoder = ResNetEncoder(name)
    assert sum(p.numel() for p in encoder.parameters()) + FC_PARAMS == TORCHVISION_PARAMS[name]
    keys = encoder.state_dict().keys()
    n_convs = 1 + 2 * sum(encoder.layer_counts) + 3  # stem, basic blocks, 3 downsamples
    assert len(keys) == n_convs * 6  # conv weight + 5 BatchNorm entries each
    for key in [
        "conv1.weight",
        "bn1.running_var",
        "layer1.0.conv2.weight",
        "layer2.0.downsample.0.weight",
        "layer4.1.bn2.num_batches_tracked",
    ]:
        assert key in keys


def test_round_trip_strict_names(tmp_path: Path) -> None:
    torch.manual_seed(1)
    source = ResNetEncoder("resnet34")
    path = torchvision_file(source, tmp_path / "resnet34.pth")
    target = ResNetEncoder("resnet34")
    load_torchvision_weights(target, path)
    for key, value in source.state_dict().items():
        assert torch.equal(target.state_dict()[key], value), key


def test_vertexnet_loads_and_freezes(tmp_path: Path) -> None:
    torch.manual_seed(2)
    source = ResNetEncoder("resnet34")
    path = torchvision_file(source, tmp_path / "resnet34.pth")
    net = VertexNet(weights=path, freeze_encoder=True)
    assert torch.equal(net.encoder.layer3[5].conv2.weight, source.layer3[5].conv2.weight)
    assert net.encoder_frozen and net.describe()["weights"] == str(path)
    assert net.describe()["params_trainable"] == 19_953_520


def test_missing_file(tmp_path: Path) -> None:
    with pytest.raises(FileNotFoundError, match=r"not found: .*absent\.pth"):
        VertexNet(encoder="resnet18", weights=tmp_path / "absent.pth")


def test_imagenet_file_absent_names_path_and_url(tmp_path: Path, monkeypatch) -> None:
    monkeypatch.setattr(torch.hub, "get_dir", lambda: str(tmp_path))
    with pytest.raises(FileNotFoundError) as err:
        VertexNet(encoder="resnet34", weights="imagenet")
    expected = tmp_path / "checkpoints" / "resnet34-b627a593.pth"
    assert str(expected) in str(err.value)
    assert "https://download.pytorch.org/models/resnet34-b627a593.pth" in str(err.value)


def test_imagenet_file_in_hub_cache_is_used(tmp_path: Path, monkeypatch) -> None:
    monkeypatch.setattr(torch.hub, "get_dir", lambda: str(tmp_path))
    (tmp_path / "checkpoints").mkdir()
    torchvision_file(
        ResNetEncoder("resnet18"), tmp_path / "checkpoints" / IMAGENET_FILES["resnet18"]
    )
    net = VertexNet(encoder="resnet18", weights="imagenet", decoder_width=0.25)
    assert net.encoder_frozen and net.weights_path.name == "resnet18-f37072fd.pth"


def test_wrong_architecture_lists_missing_keys(tmp_path: Path) -> None:
    path = torchvision_file(ResNetEncoder("resnet18"), tmp_path / "resnet18.pth")
    with pytest.raises(ValueError, match=r"missing keys \(\d+\): layer1\.2\.conv1\.weight"):
        load_torchvision_weights(ResNetEncoder("resnet34"), path)


def test_unexpected_and_mismatched_keys_are_named(tmp_path: Path) -> None:
    state = dict(ResNetEncoder("resnet18").state_dict())
    state["conv1.weight"] = torch.zeros(64, 1, 7, 7)
    state["extra.weight"] = torch.zeros(3)
    torch.save(state, tmp_path / "bad.pth")
    with pytest.raises(ValueError) as err:
        load_torchvision_weights(ResNetEncoder("resnet18"), tmp_path / "bad.pth")
    message = str(err.value)
    assert "unexpected keys (1): extra.weight" in message
    assert "conv1.weight: file (64, 1, 7, 7) vs model (64, 3, 7, 7)" in message
    assert "missing" not in message


def test_not_a_state_dict(tmp_path: Path) -> None:
    torch.save([1, 2, 3], tmp_path / "list.pth")
    with pytest.raises(ValueError, match="does not hold a state_dict"):
        load_torchvision_weights(ResNetEncoder("resnet18"), tmp_path / "list.pth")
