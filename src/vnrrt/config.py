"""Configuration: Hydra composition of ``conf/`` and typed, validated sections.

``conf/`` is the single source of truth. DVC composes it into ``params.yaml`` on
``dvc exp run`` (``hydra.enabled``); :func:`compose` does the same composition here (used
by ``make params`` and by the test that keeps the committed ``params.yaml`` in sync).
Stages read ``params.yaml`` with :func:`load_params` and validate the sections they use
against the dataclasses below, so an unknown key or a wrong type fails with a message
that names the key.
"""

from __future__ import annotations

import dataclasses
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, TypeVar

from omegaconf import DictConfig, OmegaConf
from omegaconf.errors import OmegaConfBaseException

from vnrrt.maps.shapes import SHAPES

REPO_ROOT = Path(__file__).resolve().parents[2]
CONF_DIR = Path(os.environ.get("VNRRT_CONF_DIR", REPO_ROOT / "conf"))

T = TypeVar("T")


class ConfigError(ValueError):
    """A configuration value or key is invalid; the message names it."""


@dataclass
class DataConfig:
    """Random floor maps (paper, Experiments/Data). Sizes and distances in pixels."""

    size: int = 200
    n_obstacles: list[int] = field(default_factory=lambda: [8, 18])  # [min, max] per map
    shapes: list[str] = field(default_factory=lambda: list(SHAPES))
    obstacle_size: list[float] = field(default_factory=lambda: [14.0, 44.0])  # [min, max]
    bar_width: list[float] = field(default_factory=lambda: [4.0, 9.0])  # [min, max]
    n_starts: int = 12
    n_goals: int = 12
    min_start_goal_distance: float = 20.0
    min_free_fraction: float = 0.5  # of the map, in the start/goal component
    max_attempts: int = 50
    train_fraction: float = 0.7

    def validate(self) -> None:
        """Raise :class:`ConfigError` naming the first inconsistent value."""
        _check(self.size >= 16, "data.size", self.size, "must be >= 16")
        _check(self.size <= 65535, "data.size", self.size, "must fit uint16 cells")
        for name in ("n_obstacles", "obstacle_size", "bar_width"):
            lo_hi = getattr(self, name)
            ok = len(lo_hi) == 2 and 0 <= lo_hi[0] <= lo_hi[1]
            _check(ok, f"data.{name}", lo_hi, "must be [min, max] with 0 <= min <= max")
        unknown = sorted(set(self.shapes) - set(SHAPES))
        _check(not unknown and self.shapes, "data.shapes", unknown, f"known: {SHAPES}")
        _check(1 <= self.n_starts <= 255, "data.n_starts", self.n_starts, "must be 1..255")
        _check(1 <= self.n_goals <= 255, "data.n_goals", self.n_goals, "must be 1..255")
        _check(0 < self.train_fraction < 1, "data.train_fraction", self.train_fraction, "in (0,1)")
        _check(self.max_attempts >= 1, "data.max_attempts", self.max_attempts, "must be >= 1")


@dataclass
class LabelsConfig:
    """Vertex labelling (paper, Method/Ground Truth)."""

    vertex_steps: list[int] = field(default_factory=lambda: [1, 2, 3])

    def validate(self) -> None:
        ok = bool(self.vertex_steps) and all(k >= 1 for k in self.vertex_steps)
        _check(ok, "labels.vertex_steps", self.vertex_steps, "must be positive step sizes")


@dataclass
class ScaleConfig:
    """How much data: ``len(shards) * maps_per_shard`` maps, 144 instances each by default."""

    name: str = "quick"
    maps_per_shard: int = 50
    shards: list[int] = field(default_factory=lambda: [0, 1, 2, 3])

    def validate(self) -> None:
        _check(self.maps_per_shard >= 1, "scale.maps_per_shard", self.maps_per_shard, ">= 1")
        ok = len(set(self.shards)) == len(self.shards) and all(s >= 0 for s in self.shards)
        _check(ok and self.shards, "scale.shards", self.shards, "unique non-negative ids")

    @property
    def n_maps(self) -> int:
        return len(self.shards) * self.maps_per_shard


def check_parts(parts, key: str) -> list[int]:
    """``parts`` (the ids of a stage's parts, e.g. ``eval.parts``) as a list of ints;
    :class:`ConfigError` naming ``key`` unless it is ``[0, 1, ..., K-1]`` with K >= 1."""
    try:
        ids = None if isinstance(parts, str) else [int(p) for p in parts]
    except (TypeError, ValueError):
        ids = None
    _check(bool(ids) and ids == list(range(len(ids))), key, parts, "must be [0, 1, ..., K-1]")
    return ids


def _check(ok: bool, key: str, value: Any, why: str) -> None:
    if not ok:
        raise ConfigError(f"invalid config value {key}={value!r}: {why}")


def section(cfg: DictConfig | dict, key: str, schema: type[T]) -> T:
    """Return ``cfg[key]`` as a validated ``schema`` instance.

    Unknown keys, missing sections and wrong types raise :class:`ConfigError` naming the
    offending ``key.subkey``.
    """
    node = cfg.get(key) if isinstance(cfg, DictConfig | dict) else None
    if node is None:
        raise ConfigError(f"config section {key!r} is missing")
    try:
        merged = OmegaConf.merge(OmegaConf.structured(schema), node)
        obj = OmegaConf.to_object(merged)
    except OmegaConfBaseException as err:
        where = f"{key}.{err.full_key}" if getattr(err, "full_key", None) else key
        raise ConfigError(f"bad config at {where!r}: {err.msg}") from None
    obj.validate()
    return obj


def load_params(path: str | Path = "params.yaml") -> DictConfig:
    """Load the composed parameters file (``params.yaml``) written by DVC or ``make params``."""
    path = Path(path)
    if not path.is_file():
        raise ConfigError(f"parameters file {path} not found (run `make params`)")
    cfg = OmegaConf.load(path)
    if not isinstance(cfg, DictConfig):
        raise ConfigError(f"parameters file {path} must hold a mapping")
    return cfg


def compose(overrides: list[str] | tuple[str, ...] = ()) -> DictConfig:
    """Compose ``conf/config.yaml`` with Hydra overrides and resolve it, exactly as DVC does."""
    from hydra import compose as hydra_compose
    from hydra import initialize_config_dir

    with initialize_config_dir(str(CONF_DIR), version_base=None):
        cfg = hydra_compose(config_name="config", overrides=list(overrides))
    OmegaConf.resolve(cfg)
    return cfg


def dump(cfg: DictConfig) -> str:
    """YAML text of a composed config, in the format DVC writes ``params.yaml``."""
    return OmegaConf.to_yaml(cfg)


def asdict(obj: Any) -> dict:
    """Plain dict of a config dataclass (for hashing and metadata)."""
    return dataclasses.asdict(obj)


if __name__ == "__main__":  # python -m vnrrt.config [overrides...] > params.yaml
    import sys

    sys.stdout.write(dump(compose(sys.argv[1:])))
