"""Fit one network with ready objects (a LightningModule, a DataModule and a Trainer) and
write its outputs: the final checkpoint (atomically), the metrics JSON and, through the
trainer's MLflow logger, the run. Nothing here reads configuration;
:mod:`vnrrt.pipeline.training` builds the objects from it.
"""

from __future__ import annotations

import io
import logging
import os
import time
from pathlib import Path

import lightning as L
import torch

from vnrrt.infra.io import write_json

log = logging.getLogger(__name__)


BF16_CPU_FLAGS = ("avx512_bf16", "amx_bf16")  # /proc/cpuinfo flags of native bf16 math


def cpu_bf16_flags(cpuinfo: str | Path = "/proc/cpuinfo") -> set[str] | None:
    """Which of :data:`BF16_CPU_FLAGS` the CPU has (from Linux's x86 ``cpuinfo``); None when
    that file cannot be read or has no ``flags`` line (another system: unknown)."""
    try:
        text = Path(cpuinfo).read_text()
    except OSError:
        return None
    for line in text.splitlines():
        if line.startswith("flags") and ":" in line:
            return set(BF16_CPU_FLAGS) & set(line.split(":", 1)[1].split())
    return None


def resolve_precision(precision: str | int, accelerator: str, cpuinfo="/proc/cpuinfo") -> str | int:
    """``"auto"``: ``"bf16-mixed"`` when training on a CUDA GPU, else ``"32-true"``. Any
    other value is used as it is (``conf/`` decides), with a warning when it is a bf16 mode on
    a CPU without native bf16 (emulated there: 7.4 s a step of the CPU scale's tiny network
    against 0.7 s in fp32 on a 2-core AVX2 EPYC), naming the override that trains in fp32."""
    gpu = accelerator in ("gpu", "cuda") or (accelerator == "auto" and torch.cuda.is_available())
    if str(precision) == "auto":
        return "bf16-mixed" if gpu else "32-true"
    if str(precision).startswith("bf16") and not gpu and cpu_bf16_flags(cpuinfo) == set():
        log.warning(
            "trainer.precision=%s on a CPU without native bf16 (no %s in %s): autocast is "
            "emulated, about 10x slower than fp32; `-S trainer.precision=32-true` trains in "
            "fp32 (other weights than a bf16 run's)", precision, " or ".join(BF16_CPU_FLAGS),
            cpuinfo,
        )  # fmt: skip
    return precision


VOLATILE_CALLBACKS = ("Timer", "ModelCheckpoint")  # wall-clock time; paths of last.ckpt


def save_final(trainer: L.Trainer, out: Path) -> None:
    """Write the final checkpoint to ``out`` atomically (every rank calls, rank 0 writes).

    Its bytes depend only on the training: the state of the callbacks in
    :data:`VOLATILE_CALLBACKS` (elapsed wall-clock time, the path of the deleted
    ``last.ckpt``) is left out, so two identical runs write identical files. Weights,
    optimizer, scheduler and loop states are kept: training can go on from it.
    """
    tmp = out.with_name(f"{out.name}.tmp-{os.getpid()}")
    trainer.save_checkpoint(tmp)
    if not trainer.is_global_zero:
        return
    ckpt = torch.load(tmp, map_location="cpu", weights_only=True)
    kept = {k: v for k, v in ckpt.get("callbacks", {}).items()
            if not k.startswith(VOLATILE_CALLBACKS)}  # fmt: skip
    ckpt["callbacks"] = kept
    buffer = io.BytesIO()  # an in-memory file: the archive's inner name is fixed ("archive")
    torch.save(ckpt, buffer)
    tmp.write_bytes(buffer.getvalue())
    os.replace(tmp, out)


def validation_metrics(trainer: L.Trainer) -> dict[str, float]:
    """The last validation's metrics (``val/...``) of a fitted trainer; read them before
    ``trainer.test``, which replaces the trainer's ``callback_metrics``."""
    return {k: float(v) for k, v in trainer.callback_metrics.items() if k.startswith("val/")}


def summary(
    trainer: L.Trainer,
    tested: dict,
    seconds: float,
    batch_size: int,
    first_step: int = 0,
    val: dict | None = None,
) -> dict:
    """Metrics of a run: the final validation's metrics (``val``: :func:`validation_metrics`
    read after fitting; None: those left in the trainer, none after a test), test metrics,
    steps, time, throughput. ``first_step``: the step a resumed run started from;
    ``fit_seconds`` and the throughput are those of this run's steps only."""
    val = validation_metrics(trainer) if val is None else val
    per_step = batch_size * trainer.world_size
    return {
        **val,
        **{k: float(v) for k, v in tested.items()},
        "epochs": trainer.current_epoch,
        "steps": trainer.global_step,
        "resumed_from_step": first_step,
        "train_images": trainer.global_step * per_step,
        "fit_seconds": seconds,
        "train_images_per_s": (trainer.global_step - first_step) * per_step / max(seconds, 1e-9),
    }


def resumed_step(checkpoint: Path | None) -> int:
    """The global step a Lightning checkpoint was saved at (0 for none)."""
    if checkpoint is None:
        return 0
    from vnrrt.model.checkpoint import read_checkpoint

    return int(read_checkpoint(checkpoint)["global_step"])


def fit(
    module: L.LightningModule,
    datamodule: L.LightningDataModule,
    trainer: L.Trainer,
    out: Path,
    metrics_file: Path,
    batch_size: int,
    resume: Path | None = None,
    with_val: bool = False,
) -> dict:
    """Train ``module`` (from ``resume``, a Lightning checkpoint, if given), write the final
    checkpoint to ``out``, test it and write the metrics to ``metrics_file``; returns them.
    ``with_val``: with the final validation's metrics (``val/...``; the budget curve's
    trainings: its report, the target variants' selection). The test metrics reach no
    logger here: the run logs them once, linked to the logged model
    (:func:`vnrrt.pipeline.training.finish_run`)."""
    first_step = resumed_step(resume)  # before the run overwrites its last.ckpt
    start = time.perf_counter()
    trainer.fit(module, datamodule=datamodule, ckpt_path=None if resume is None else str(resume))
    seconds = time.perf_counter() - start
    val = validation_metrics(trainer) if with_val else {}  # before the test replaces them
    out.parent.mkdir(parents=True, exist_ok=True)
    save_final(trainer, out)
    loggers, trainer.loggers = trainer.loggers, []
    try:
        tested = trainer.test(module, datamodule=datamodule, verbose=False)[0]
    finally:
        trainer.loggers = loggers
    metrics = summary(trainer, tested, seconds, batch_size, first_step, val)
    if trainer.is_global_zero:
        write_json(metrics_file, metrics)
        log.info("%s: %s", out.stem, {k: round(v, 4) for k, v in metrics.items()})
    return metrics
