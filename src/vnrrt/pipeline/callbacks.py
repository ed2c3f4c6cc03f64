"""Lightning callbacks of the training runs: progress in logs, and the per-epoch figure.

* :func:`progress_callback`: a live tqdm bar on a terminal; in non-TTY logs (``dvc repro >
  log``, CI) no bar but one :class:`LogProgress` line every ``every_n_steps`` steps and one
  per validation.
* :class:`PredictionFigures`: after each validation epoch, input, ground truth and predicted
  heatmap of the first validation instances (the paper's Fig. 3) as an MLflow image
  ``val_predictions`` at the epoch's step (the run page's image grid has a step slider).
"""

from __future__ import annotations

import logging
import sys
import time

import lightning as L
from lightning.pytorch.callbacks import Callback, TQDMProgressBar
from lightning.pytorch.loggers import MLFlowLogger

log = logging.getLogger(__name__)
IMAGE_KEY = "val_predictions"  # the MLflow image of PredictionFigures


class LogProgress(Callback):
    """Training progress as ``logging`` lines (rank zero only): step, loss and images/s every
    ``every_n_steps`` steps, and the epoch's validation metrics."""

    def __init__(self, every_n_steps: int = 50) -> None:
        self.every = max(1, every_n_steps)
        self._t0, self._images = 0.0, 0

    def on_train_epoch_start(self, trainer: L.Trainer, pl_module: L.LightningModule) -> None:
        self._t0, self._images = time.perf_counter(), 0

    def on_train_batch_end(self, trainer, pl_module, outputs, batch, batch_idx) -> None:
        self._images += len(batch["image"])
        total = trainer.num_training_batches
        if not trainer.is_global_zero or ((batch_idx + 1) % self.every and batch_idx + 1 != total):
            return
        rate = self._images / max(time.perf_counter() - self._t0, 1e-9)
        loss = float(outputs["loss"])
        log.info("epoch %d step %d/%s: loss %.4f, %.1f images/s per process",
                 trainer.current_epoch, batch_idx + 1, total, loss, rate)  # fmt: skip

    def on_validation_epoch_end(self, trainer: L.Trainer, pl_module: L.LightningModule) -> None:
        if trainer.sanity_checking or not trainer.is_global_zero:
            return
        shown = {k: float(v) for k, v in trainer.callback_metrics.items() if k.startswith("val/")}
        text = ", ".join(f"{k[4:]} {v:.4f}" for k, v in sorted(shown.items()))
        log.info("epoch %d validation: %s", trainer.current_epoch, text)


def progress_callback(every_n_steps: int = 50) -> Callback:
    """A tqdm bar on a terminal, else :class:`LogProgress` (the ``callbacks.progress`` entry;
    the training stage enables Lightning's bar only for the former)."""
    if sys.stderr.isatty():
        return TQDMProgressBar(refresh_rate=1)
    return LogProgress(every_n_steps)


class PredictionFigures(Callback):
    """Log a figure of the first ``n`` validation instances after every validation epoch to
    each :class:`MLFlowLogger` of the trainer (rank zero; skipped in the sanity check)."""

    def __init__(self, n: int = 4) -> None:
        self.n = n
        self._kept: dict | None = None

    def on_validation_batch_end(self, trainer, pl_module, outputs, batch, batch_idx,
                                dataloader_idx: int = 0) -> None:  # fmt: skip
        if batch_idx or trainer.sanity_checking or not trainer.is_global_zero:
            return
        keys = ("classes", "target", "vertices", "key")
        self._kept = {k: batch[k][: self.n].cpu().numpy() for k in keys}
        self._kept["probs"] = outputs["probs"][: self.n].float().cpu().numpy()

    def on_validation_epoch_end(self, trainer: L.Trainer, pl_module: L.LightningModule) -> None:
        loggers = [lg for lg in trainer.loggers if isinstance(lg, MLFlowLogger)]
        if self._kept is None or not loggers:
            return
        from vnrrt.maps.render import colorize
        from vnrrt.viz.common import close, rgb_image
        from vnrrt.viz.training import prediction_figure

        k = self._kept
        titles = [f"shard {s}, instance {i}" for s, i in k["key"]]
        fig = prediction_figure(colorize(k["classes"]), k["target"], k["vertices"], k["probs"],
                                titles)  # fmt: skip
        image = rgb_image(fig)
        close(fig)
        for lg in loggers:
            lg.experiment.log_image(lg.run_id, image, key=IMAGE_KEY, step=trainer.current_epoch)
        self._kept = None
