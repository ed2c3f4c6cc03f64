"""Every conf/model/*.yaml composes and instantiates a network and its loss."""

from pathlib import Path

import pytest
import torch
from hydra import compose, initialize_config_dir
from hydra.utils import instantiate

from vnrrt.model import FocalLoss, VertexNet

CONF = Path(__file__).resolve().parents[2] / "conf"
MODELS = sorted(p.stem for p in (CONF / "model").glob("*.yaml"))


@pytest.mark.parametrize("name", MODELS)
def test_model_config_instantiates(name: str) -> None:
    with initialize_config_dir(config_dir=str(CONF), version_base="1.3"):
        cfg = compose("config", overrides=[f"model={name}"])
    net, loss = instantiate(cfg.model.net), instantiate(cfg.model.loss)
    assert isinstance(net, VertexNet) and isinstance(loss, FocalLoss)
    assert loss.gamma == 2.0
    assert net.encoder_frozen is False  # no weights by default: the whole network trains
    net.eval()
    with torch.no_grad():
        out = net(torch.rand(1, 3, 64, 64))
    assert out.shape == (1, cfg.model.net.out_channels, 64, 64)


def test_paper_config_is_the_paper_network() -> None:
    with initialize_config_dir(config_dir=str(CONF), version_base="1.3"):
        cfg = compose("config", overrides=["model=vertexnet"])
    assert cfg.model.net.encoder == "resnet34" and cfg.model.net.decoder_width == 1.0
    assert cfg.model.net.freeze_encoder is True and cfg.model.net.weights is None
