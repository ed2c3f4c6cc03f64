"""Small datasets and configs for the training tests (shards, manifest, named maps in a tmp dir)."""

from __future__ import annotations

from pathlib import Path

from omegaconf import DictConfig

from vnrrt.config import compose, section
from vnrrt.data.build import build_shard
from vnrrt.data.build_named import build_named_maps
from vnrrt.data.config import LabelsConfig
from vnrrt.data.manifest import build_manifest
from vnrrt.data.shards import shard_file
from vnrrt.maps.config import DataConfig

# The smoke scale on 64x64 maps: the same pipeline, about 10x cheaper per image than 200x200.
SMALL = [
    "scale=smoke",
    "data.size=64",
    "data.n_obstacles=[2,4]",
    "data.obstacle_size=[6.0,14.0]",
    "data.bar_width=[2.0,4.0]",
    "data.min_start_goal_distance=10.0",
]
# One epoch of two training batches and one validation batch.
QUICK = ["trainer.max_epochs=1", "trainer.limit_train_batches=2", "trainer.limit_val_batches=1"]


def build_data(root: Path, overrides: list[str]) -> Path:
    """Shards, manifest and named maps of the composed ``overrides`` under ``root``."""
    cfg = compose(overrides)
    data, labels = section(cfg, "data", DataConfig), section(cfg, "labels", LabelsConfig)
    for s in cfg.scale.shards:
        build_shard(shard_file(root / "shards", s), s, int(cfg.seed), cfg.scale.maps_per_shard,
                    data, labels, workers=1)  # fmt: skip
    build_manifest(root / "shards", list(cfg.scale.shards), root / "manifest.json")
    build_named_maps(root / "named_maps.npz", data.size, labels)
    return root


def paths(data: Path, out: Path) -> list[str]:
    """Overrides reading the data in ``data`` and writing every output under ``out``."""
    return [
        f"paths.shards={data / 'shards'}",
        f"paths.manifest={data / 'manifest.json'}",
        f"paths.named_maps={data / 'named_maps.npz'}",
        f"paths.models={out / 'models'}",
        f"paths.metrics={out / 'metrics'}",
        f"paths.figures={out / 'figures'}",
        f"paths.heatmaps={out / 'heatmaps'}",
        f"paths.timing={out / 'timing'}",
        f"paths.instances={out / 'instances.npz'}",
        f"paths.budget={out / 'budget'}",
        f"paths.budget_report={out / 'training_budget.md'}",
        f"logger.uri=sqlite:///{out / 'mlflow.db'}",
        f"logger.artifact_location={out / 'mlartifacts'}",
    ]


def small_cfg(data: Path, out: Path, *overrides: str) -> DictConfig:
    """The smoke config on the 64x64 data, outputs in ``out``, MLflow off unless overridden."""
    return compose([*SMALL, *paths(data, out), "logger.enabled=false", *overrides])
