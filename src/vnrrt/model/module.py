"""The LightningModule training VertexNet (or the NRRT* network) with focal loss.

It receives ready objects, as in lightning-hydra-template: the network, the loss and the
optimizer / scheduler *factories* (``_partial_: true`` in config). One :meth:`model_step`
serves train, val and test; each split has its own metric collection
(:func:`vnrrt.model.metrics.metric_collection`) logged per epoch as ``<split>/<metric>``.
"""

from __future__ import annotations

import inspect
from collections.abc import Callable
from typing import Any

import lightning as L
import torch
from torch import Tensor, nn

from vnrrt.model.metrics import LABEL_MASKS, metric_collection
from vnrrt.model.record import DIGEST_KEY, RECORD_KEY, record_digest

SPLITS = ("train", "val", "test")


class VertexNetModule(L.LightningModule):
    """Args:
    net: ``(B, 3, H, W)`` image -> ``(B, 2, H, W)`` logits (:class:`vnrrt.model.VertexNet`).
    loss: ``(logits, target (B, H, W))`` -> scalar (:class:`vnrrt.model.FocalLoss`).
    optimizer: factory ``params -> torch.optim.Optimizer``.
    scheduler: optional factory ``optimizer -> LRScheduler``; ``total_steps`` is filled in
        from the trainer when the scheduler takes it and the factory leaves it unset.
    scheduler_interval: ``"step"`` or ``"epoch"``.
    metric_radius, metric_tau, metric_ap_radius, metric_endpoint_radius: "within r pixels",
        the probability threshold, the AP targets' dilation and the start/goal disks of the
        metrics (:func:`vnrrt.model.metrics.heatmap_metric_set`).
    train_metrics_every: update the training metrics on every n-th batch only (they cost
        about a quarter of a CPU step; loss is logged on every batch).
    channels_last: use the channels-last memory format (faster on CUDA with bf16, and on
        CPU: ``benchmarks/bench_cpu_training.py``).
    record: what the checkpoint must remember to rebuild and check the network (config of
        ``net``, target, rendering); stored under ``checkpoint["vnrrt"]``.
    """

    def __init__(self, net: nn.Module, loss: nn.Module, optimizer: Callable, scheduler=None,
                 scheduler_interval: str = "step", metric_radius: float = 3.0,
                 metric_tau: float = 0.5, metric_ap_radius: float = 1.0,
                 metric_endpoint_radius: float = 3.0, channels_last: bool = True,
                 train_metrics_every: int = 1,
                 record: dict[str, Any] | None = None) -> None:  # fmt: skip
        super().__init__()
        if train_metrics_every < 1:
            raise ValueError(f"train_metrics_every must be >= 1, got {train_metrics_every!r}")
        if scheduler_interval not in ("step", "epoch"):
            raise ValueError(f"scheduler_interval must be step or epoch: {scheduler_interval!r}")
        self.net, self.loss_fn = net, loss
        self.optimizer_factory, self.scheduler_factory = optimizer, scheduler
        self.scheduler_interval = scheduler_interval
        for split in SPLITS:  # train_metrics, val_metrics, test_metrics
            metrics = metric_collection(
                metric_radius, metric_tau, metric_ap_radius, metric_endpoint_radius
            ).clone(prefix=f"{split}/")
            setattr(self, f"{split}_metrics", metrics)
        self.channels_last, self.train_metrics_every = channels_last, train_metrics_every
        self.record = dict(record or {})

    def forward(self, image: Tensor) -> Tensor:
        """image ``(B, 3, H, W)`` -> logits ``(B, 2, H, W)``."""
        if self.channels_last:
            image = image.contiguous(memory_format=torch.channels_last)
        return self.net(image)

    def on_fit_start(self) -> None:
        if self.channels_last:
            self.net.to(memory_format=torch.channels_last)

    def model_step(self, batch: dict[str, Tensor]) -> tuple[Tensor, Tensor]:
        """Loss (scalar) and positive-class probabilities ``(B, H, W)`` of one batch."""
        logits = self(batch["image"])  # (B, 2, H, W)
        loss = self.loss_fn(logits, batch["target"])
        probs = logits.float().softmax(dim=1)[:, 1]  # (B, H, W)
        return loss, probs

    def _step(self, batch: dict[str, Tensor], split: str, batch_idx: int = 0) -> dict[str, Tensor]:
        loss, probs = self.model_step(batch)
        metrics = getattr(self, f"{split}_metrics")
        train = split == "train"
        if not train or batch_idx % self.train_metrics_every == 0:
            metrics.update(
                preds=probs.detach(), target=batch["target"],
                **{k: batch[k] for k in LABEL_MASKS},
            )  # fmt: skip
        n = len(batch["image"])
        self.log(f"{split}/loss", loss, on_step=train, on_epoch=True, prog_bar=True,
                 batch_size=n, sync_dist=not train)  # fmt: skip
        self.log_dict(metrics, on_step=False, on_epoch=True, batch_size=n)
        return {"loss": loss, "probs": probs.detach()}

    def training_step(self, batch: dict[str, Tensor], batch_idx: int) -> dict[str, Tensor]:
        return self._step(batch, "train", batch_idx)

    def validation_step(self, batch: dict[str, Tensor], batch_idx: int) -> dict[str, Tensor]:
        return self._step(batch, "val")

    def test_step(self, batch: dict[str, Tensor], batch_idx: int) -> dict[str, Tensor]:
        return self._step(batch, "test")

    def configure_optimizers(self) -> dict[str, Any]:
        params = [p for p in self.parameters() if p.requires_grad]
        optimizer = self.optimizer_factory(params=params)
        if self.scheduler_factory is None:
            return {"optimizer": optimizer}
        kwargs = {}
        func = getattr(self.scheduler_factory, "func", self.scheduler_factory)
        keywords = getattr(self.scheduler_factory, "keywords", {})
        if "total_steps" in inspect.signature(func).parameters and "total_steps" not in keywords:
            kwargs["total_steps"] = int(self.trainer.estimated_stepping_batches)
        scheduler = self.scheduler_factory(optimizer=optimizer, **kwargs)
        return {
            "optimizer": optimizer,
            "lr_scheduler": {"scheduler": scheduler, "interval": self.scheduler_interval},
        }

    def on_save_checkpoint(self, checkpoint: dict[str, Any]) -> None:
        """Store the record, sealed with :func:`record_digest` of the weights being saved."""
        record = {k: v for k, v in self.record.items() if k != DIGEST_KEY}
        checkpoint[RECORD_KEY] = {
            **record,
            DIGEST_KEY: record_digest(record, checkpoint["state_dict"]),
        }
