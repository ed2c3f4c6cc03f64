"""The training config groups compose, instantiate, and pick the right network per scale."""

import logging

import lightning as L
import pytest
from hydra.utils import instantiate

from tests.train_helpers import SMALL
from vnrrt.config import CONF_DIR, compose
from vnrrt.data.datamodule import ShardDataModule
from vnrrt.model.module import VertexNetModule
from vnrrt.pipeline.callbacks import LogProgress, progress_callback
from vnrrt.training.train import cpu_bf16_flags, resolve_precision

TRAINERS = sorted(p.stem for p in (CONF_DIR / "trainer").glob("*.yaml"))


@pytest.mark.parametrize("name", TRAINERS)
def test_every_trainer_config_composes(name):
    cfg = compose([f"trainer={name}"])
    assert cfg.trainer._target_ == "lightning.Trainer"
    if name in ("default", "cpu"):  # the others need a GPU or several processes
        precision = resolve_precision(cfg.trainer.precision, cfg.trainer.accelerator)
        trainer = instantiate(cfg.trainer, precision=precision, logger=False,
                              enable_progress_bar=False, _convert_="all")  # fmt: skip
        assert isinstance(trainer, L.Trainer) and trainer.max_epochs == cfg.trainer.max_epochs


def test_module_and_datamodule_configs_instantiate():
    cfg = compose(SMALL)
    dm = instantiate(cfg.train.datamodule, target="path", target_radius=1.0)
    assert isinstance(dm, ShardDataModule) and dm.item_args["target"] == "path"
    make = instantiate(cfg.train.module, _partial_=True)
    module = make(net=instantiate(cfg.model.net), loss=instantiate(cfg.model.loss))
    assert isinstance(module, VertexNetModule)
    optimizer = module.optimizer_factory(params=module.parameters())
    assert optimizer.defaults["lr"] == cfg.train.module.optimizer.lr


@pytest.mark.parametrize(
    ("scale", "encoder", "encoder_width", "precision"),
    [("smoke", "resnet18", 0.5, "32-true"), ("quick", "resnet18", 0.5, "auto"),
     ("paper", "resnet34", 1.0, "bf16-mixed")],
)  # fmt: skip
def test_scales_pick_the_network_and_precision(scale, encoder, encoder_width, precision):
    cfg = compose([f"scale={scale}"])
    assert cfg.model.net.encoder == encoder and cfg.model.net.encoder_width == encoder_width
    assert cfg.trainer.precision == precision
    assert cfg.networks.vertexnet.target == "vertex" and cfg.networks.nrrtnet.target == "path"
    assert cfg.model.loss.gamma == 2.0
    paper = compose([f"scale={scale}", "model=vertexnet"])  # the command line wins
    assert paper.model.net.encoder == "resnet34" and paper.model.net.prior is None


def test_precision_is_bf16_on_gpu_and_32_on_cpu():
    assert resolve_precision("auto", "cpu") == "32-true"
    assert resolve_precision("auto", "gpu") == "bf16-mixed"
    assert resolve_precision("16-mixed", "gpu") == "16-mixed"


def test_non_tty_logs_get_log_lines_instead_of_a_bar():
    assert isinstance(progress_callback(10), LogProgress)  # pytest captures stderr: no TTY


def test_bf16_on_a_cpu_without_native_bf16_is_kept_and_warned_about(tmp_path, caplog):
    """conf/ decides the precision; a bf16 mode on a CPU whose flags lack avx512_bf16 and
    amx_bf16 is used as asked, with a warning naming the fp32 override."""
    avx2, native = tmp_path / "avx2", tmp_path / "native"
    avx2.write_text("processor\t: 0\nflags\t\t: fpu sse2 avx avx2 fma\n\nflags\t: fpu avx2\n")
    native.write_text("processor\t: 0\nflags\t\t: fpu avx2 avx512f avx512_bf16 amx_bf16\n")
    with caplog.at_level(logging.WARNING, logger="vnrrt.training.train"):
        assert resolve_precision("bf16-mixed", "cpu", avx2) == "bf16-mixed"
    assert "without native bf16" in caplog.text and "trainer.precision=32-true" in caplog.text
    caplog.clear()
    with caplog.at_level(logging.WARNING, logger="vnrrt.training.train"):
        assert resolve_precision("bf16-mixed", "cpu", native) == "bf16-mixed"
        assert resolve_precision("bf16-mixed", "cpu", tmp_path / "absent") == "bf16-mixed"
        assert resolve_precision("32-true", "cpu", avx2) == "32-true"
        assert resolve_precision("auto", "cpu", avx2) == "32-true"
    assert caplog.text == ""
    assert cpu_bf16_flags(native) == {"avx512_bf16", "amx_bf16"} and cpu_bf16_flags(avx2) == set()
    arm = tmp_path / "arm"
    arm.write_text("processor\t: 0\nFeatures\t: fp asimd bf16\n")
    assert cpu_bf16_flags(arm) is None  # not x86: unknown, no warning
