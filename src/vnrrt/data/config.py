"""The ``labels`` and ``scale`` config sections: typed mirrors of ``conf/labels`` and
``conf/scale``."""

from __future__ import annotations

from dataclasses import dataclass

from vnrrt.config import check, conf_defaults


@dataclass
@conf_defaults("labels")
class LabelsConfig:
    """Vertex labelling (paper, Method/Ground Truth)."""

    vertex_steps: list[int]
    tie_break: str  # among equally short A* paths: turns | line | exact
    tie_tolerance: float  # px: line/exact keep the direction while this near the guide

    def validate(self) -> None:
        ok = bool(self.vertex_steps) and all(k >= 1 for k in self.vertex_steps)
        check(ok, "labels.vertex_steps", self.vertex_steps, "must be positive step sizes")
        known = ("turns", "line", "exact")
        check(self.tie_break in known, "labels.tie_break", self.tie_break, f"one of {known}")
        check(self.tie_tolerance >= 0, "labels.tie_tolerance", self.tie_tolerance, "must be >= 0")


@dataclass
@conf_defaults("scale", "quick", node="scale")
class ScaleConfig:
    """How much data: ``len(shards) * maps_per_shard`` maps, 144 instances each by default."""

    name: str
    maps_per_shard: int
    shards: list[int]

    def validate(self) -> None:
        check(self.maps_per_shard >= 1, "scale.maps_per_shard", self.maps_per_shard, ">= 1")
        ok = len(set(self.shards)) == len(self.shards) and all(s >= 0 for s in self.shards)
        check(ok and self.shards, "scale.shards", self.shards, "unique non-negative ids")

    @property
    def n_maps(self) -> int:
        return len(self.shards) * self.maps_per_shard
