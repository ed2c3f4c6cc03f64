"""The ``eval`` config section: the typed mirror of ``conf/eval/default.yaml``."""

from __future__ import annotations

from dataclasses import dataclass, field

from vnrrt.config import ConfigError, check_parts

PLANNERS = ("rrt_star", "nrrt_star", "vnrrt_star", "m_vnrrt_star")
DEFAULT_SOURCES = {"nrrt_star": "nrrtnet", "vnrrt_star": "vertexnet", "m_vnrrt_star": "vertexnet"}


@dataclass
class EvalConfig:
    """The ``eval`` config section (paper, Experiments). Trial counts are per instance."""

    planners: list[str] = field(default_factory=lambda: list(PLANNERS))
    # planner -> heatmap source it samples (a network name of `networks`, or an oracle)
    sources: dict[str, str] = field(default_factory=lambda: dict(DEFAULT_SOURCES))
    named_initial: int = 1000  # paper: 1,000 trials per named map
    named_optimal: int = 100  # paper: 100
    random_maps: int = 1000  # paper: 1,000 random test maps (R instances), one trial each
    random_initial: int = 1
    random_optimal: int = 1
    any_angle: bool = True  # also the optimal_any_angle stop rule (exact optimum)
    parts: list[int] = field(default_factory=lambda: [0])  # trial parts: [0, 1, ..., K-1]
    informed: bool = True  # also every configuration with informed sampling (random maps)

    def validate(self) -> None:
        """Raise :class:`ConfigError` naming the first invalid value."""
        check_parts(self.parts, "eval.parts")
        for name in (
            "named_initial",
            "named_optimal",
            "random_maps",
            "random_initial",
            "random_optimal",
        ):
            value = getattr(self, name)
            if not isinstance(value, int) or value < 0:
                raise ConfigError(f"invalid config value eval.{name}={value!r}: must be >= 0")
        unknown = sorted(set(self.planners) - set(PLANNERS))
        if unknown or not self.planners:
            raise ConfigError(f"invalid eval.planners {self.planners}: known {PLANNERS}")
        for p in self.planners:
            if p != "rrt_star" and p not in self.sources:
                raise ConfigError(f"eval.sources has no heatmap source for planner {p!r}")


@dataclass
class StatsConfig:
    """The ``stats`` section: bootstrap confidence intervals of the report."""

    bootstrap: int = 2000  # resamples of every confidence interval
    level: float = 0.95  # confidence level of intervals and verdicts

    def validate(self) -> None:
        if not isinstance(self.bootstrap, int) or self.bootstrap < 100:
            raise ConfigError(f"invalid config value stats.bootstrap={self.bootstrap!r}: >= 100")
        if not 0.5 < self.level < 1:
            raise ConfigError(f"invalid config value stats.level={self.level!r}: in (0.5, 1)")
