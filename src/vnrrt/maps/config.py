"""The ``data`` config section (random floor maps): the typed mirror of
``conf/data/default.yaml``."""

from __future__ import annotations

from dataclasses import dataclass

from vnrrt.config import check, conf_defaults
from vnrrt.maps.shapes import SHAPES


@dataclass
@conf_defaults("data")
class DataConfig:
    """Random floor maps (paper, Experiments/Data). Sizes and distances in pixels."""

    size: int
    n_obstacles: list[int]  # [min, max] per map
    shapes: list[str]
    obstacle_size: list[float]  # [min, max]
    bar_width: list[float]  # [min, max]
    n_starts: int
    n_goals: int
    min_start_goal_distance: float
    min_free_fraction: float  # of the map, in the start/goal component
    max_attempts: int
    train_fraction: float

    def validate(self) -> None:
        """Raise :class:`ConfigError` naming the first inconsistent value."""
        check(self.size >= 16, "data.size", self.size, "must be >= 16")
        check(self.size <= 65535, "data.size", self.size, "must fit uint16 cells")
        for name in ("n_obstacles", "obstacle_size", "bar_width"):
            lo_hi = getattr(self, name)
            ok = len(lo_hi) == 2 and 0 <= lo_hi[0] <= lo_hi[1]
            check(ok, f"data.{name}", lo_hi, "must be [min, max] with 0 <= min <= max")
        unknown = sorted(set(self.shapes) - set(SHAPES))
        check(not unknown and self.shapes, "data.shapes", unknown, f"known: {SHAPES}")
        check(1 <= self.n_starts <= 255, "data.n_starts", self.n_starts, "must be 1..255")
        check(1 <= self.n_goals <= 255, "data.n_goals", self.n_goals, "must be 1..255")
        check(0 < self.train_fraction < 1, "data.train_fraction", self.train_fraction, "in (0,1)")
        check(self.max_attempts >= 1, "data.max_attempts", self.max_attempts, "must be >= 1")
