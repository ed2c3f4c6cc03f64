"""The evaluation's config sections, typed mirrors of ``conf/eval``, ``conf/stats``,
``conf/oracle`` and ``conf/regime``: one module, one dataclass per section.

The pipeline builds them only through :func:`vnrrt.config.section` from the composed config,
which must give every key. A library caller's defaults (``EvalConfig()``) are the group's
default file in ``conf/`` (:func:`vnrrt.config.conf_defaults`): one source, never written
again here.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from itertools import pairwise

from vnrrt.config import ConfigError, check, check_parts, conf_defaults
from vnrrt.evaluation.keys import MASK_VARIANTS, ConfigKey
from vnrrt.evaluation.oracles import ORACLE_KINDS
from vnrrt.names import PLANNERS, mask_taus

BLEND_IDEA = "blend"  # the family of the path-vertex blend (oracle.blend_weights)
HEATMAP_PLANNERS = tuple(p for p in PLANNERS if p != "rrt_star")
REGIME_RADIUS_MODES = ("shrinking", "fixed1", "fixed2")  # fixedK: a fixed near radius K x eta


def check_cap_factor(value) -> float:
    """``eval.cap_factor`` (a run's wall-clock cap over the time budget) as a float;
    :class:`ConfigError` unless it is a finite number >= 1."""
    ok = isinstance(value, int | float) and not isinstance(value, bool)
    check(ok and 1.0 <= value < math.inf, "eval.cap_factor", value, "a finite number >= 1")
    return float(value)


@dataclass
@conf_defaults("eval")
class Configurations:
    """``eval.planners``, ``eval.sources`` and ``eval.informed``: which configurations run
    (:func:`vnrrt.evaluation.protocol.configurations`), for the stages that read only these."""

    planners: list[str]
    # planner -> heatmap source it samples (a network name of `networks`, or an oracle)
    sources: dict[str, str]
    informed: bool  # also every configuration with informed sampling (random maps)
    mask_variants: list[str]  # M-VNRRT* at planner.tau with these masks too
    masked_controls: bool  # M-VNRRT* at planner.tau on the NRRT* network's heatmap
    endpoint_radius: float  # start/goal disks (px): the noends mask, the mass shares
    zero_obstacles: bool  # the obstacle rule: sample free cells only (heatmaps, uniform)
    cap_factor: float  # a run's wall-clock cap, x planner.max_seconds (applied after the run)

    def validate(self) -> None:
        """Raise :class:`ConfigError` naming the first invalid value."""
        check_cap_factor(self.cap_factor)
        bad = sorted(set(self.mask_variants) - set(MASK_VARIANTS))
        check(not bad, "eval.mask_variants", self.mask_variants, f"known: {list(MASK_VARIANTS)}")
        check(isinstance(self.masked_controls, bool), "eval.masked_controls",
              self.masked_controls, "true or false")  # fmt: skip
        check(isinstance(self.zero_obstacles, bool), "eval.zero_obstacles",
              self.zero_obstacles, "true or false")  # fmt: skip
        ok = self.endpoint_radius >= 0
        check(ok, "eval.endpoint_radius", self.endpoint_radius, "must be >= 0 px")
        if self.masked_controls:
            check("nrrt_star" in self.sources, "eval.masked_controls", True,
                  "needs eval.sources.nrrt_star (the path network)")  # fmt: skip
        unknown = sorted(set(self.planners) - set(PLANNERS))
        if unknown or not self.planners:
            raise ConfigError(f"invalid eval.planners {self.planners}: known {PLANNERS}")
        for p in self.planners:
            if p != "rrt_star" and p not in self.sources:
                raise ConfigError(f"eval.sources has no heatmap source for planner {p!r}")
        check(isinstance(self.informed, bool), "eval.informed", self.informed, "true or false")


@dataclass
@conf_defaults("eval")
class EvalConfig(Configurations):
    """The ``eval`` section (paper, Experiments). Trial counts are per instance."""

    named_initial: int  # paper: 1,000 trials per named map
    named_optimal: int  # paper: 100
    random_maps: int  # paper: 1,000 random test maps (R instances), one trial each
    random_initial: int
    random_optimal: int
    any_angle: bool  # also the optimal_any_angle stop rule (exact optimum)
    gpu: bool  # also the GPU-trained paper networks (paths.gpu_returned) as sources
    parts: list[int]  # trial parts: [0, 1, ..., K-1]
    timing_noise: bool  # the protocol's RRT* timed twice (the machine's timing noise)

    def validate(self) -> None:
        """Raise :class:`ConfigError` naming the first invalid value."""
        super().validate()
        check_parts(self.parts, "eval.parts")
        check(isinstance(self.gpu, bool), "eval.gpu", self.gpu, "true or false")
        ok = isinstance(self.timing_noise, bool)
        check(ok, "eval.timing_noise", self.timing_noise, "true or false")
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


@dataclass
@conf_defaults("planner")
class Rules:
    """``planner.eps``, ``planner.taus``, ``planner.tau`` and ``planner.max_iterations``:
    the stop tolerance, the M-VNRRT* thresholds and the iteration budget, for the stages that
    name them without planning (the budget bounds a trial table's ``iterations``:
    :mod:`vnrrt.evaluation.invariants`)."""

    eps: float
    taus: list[float]
    tau: float
    max_iterations: int  # the budget bounds a trial table's iterations

    def validate(self) -> None:
        check(self.eps >= 0, "planner.eps", self.eps, "must be >= 0")
        check(self.max_iterations > 0, "planner.max_iterations", self.max_iterations,
              "must be > 0")  # fmt: skip
        ok = all(0 < t <= 1 for t in [*self.taus, self.tau])
        check(ok, "planner.taus", [*self.taus, self.tau], "every tau must be in (0, 1]")

    @property
    def mask_taus(self) -> list[float]:
        """Every M-VNRRT* threshold of a run (:func:`mask_taus`)."""
        return mask_taus(self.taus, self.tau)


@dataclass
@conf_defaults("stats")
class StatsConfig:
    """The ``stats`` section: bootstrap confidence intervals and the verdict rules."""

    bootstrap: int  # resamples of every confidence interval
    level: float  # confidence level of intervals and verdicts (family-wise for claims)
    tail_draws: int  # bootstrap draws in each tail at the claims' corrected level
    untestable_endpoint_share: float  # a masked sampler with more on start/goal ...
    untestable_fallback: float  # ... or falling back to uniform more often: untestable
    strata: list[int]  # lower bounds of the turning-point strata (vnrrt.evaluation.strata)
    pairing: list[float]  # correlations between the paper's planners: its interval's sensitivity

    def validate(self) -> None:
        if not isinstance(self.bootstrap, int) or self.bootstrap < 100:
            raise ConfigError(f"invalid config value stats.bootstrap={self.bootstrap!r}: >= 100")
        if not 0.5 < self.level < 1:
            raise ConfigError(f"invalid config value stats.level={self.level!r}: in (0.5, 1)")
        ok = isinstance(self.tail_draws, int) and self.tail_draws >= 1
        check(ok, "stats.tail_draws", self.tail_draws, "an integer >= 1")
        for name in ("untestable_endpoint_share", "untestable_fallback"):
            v = getattr(self, name)
            check(0 < v <= 1, f"stats.{name}", v, "must be in (0, 1]")
        b = self.strata
        ok = bool(b) and all(isinstance(v, int) for v in b) and b[0] == 0
        ok = ok and all(x < y for x, y in pairwise(b))
        check(ok, "stats.strata", b, "increasing integers from 0 (turning points)")
        ok = all(0 < r < 1 for r in self.pairing)
        check(ok, "stats.pairing", self.pairing, "every correlation must be in (0, 1)")


@dataclass
@conf_defaults("oracle")
class OracleConfig:
    """The ``oracle`` section: the oracle families of the sampling-ideas study
    (:mod:`vnrrt.studies.sampling_ideas`)."""

    families: dict[str, list[str]]
    planners: dict[str, str]  # idea -> the planner sampling its oracles (others: vnrrt_star)
    sigmas: list[float]
    mixes: list[float]
    blend_weights: list[float]
    floor: float
    radius: float
    qualities: list[float]
    random_maps: int
    selection_share: float
    trials: int
    per_cell: bool  # also select in every regime cell (the selection instances, optimal stops)
    parts: list[int]

    def planner_of(self, idea: str) -> str:
        """The planner that samples family ``idea``'s oracles (``oracle.planners``;
        ``vnrrt_star`` where it names none)."""
        return self.planners.get(idea, "vnrrt_star")

    def validate(self) -> None:
        check(set(self.families) >= {"path", "vertex"}, "oracle.families", list(self.families),
              "needs the path and vertex ideas")  # fmt: skip
        for idea, kinds in self.families.items():
            bad = sorted(set(kinds) - set(ORACLE_KINDS))
            ok = bool(kinds) and not bad
            check(ok, f"oracle.families.{idea}", kinds, f"known: {ORACLE_KINDS}")
        ideas = {*self.families, BLEND_IDEA}
        for idea, planner in self.planners.items():
            check(idea in ideas, f"oracle.planners.{idea}", planner,
                  f"names no family of {sorted(ideas)}")  # fmt: skip
            ok = planner in HEATMAP_PLANNERS
            check(ok, f"oracle.planners.{idea}", planner, f"known: {HEATMAP_PLANNERS}")
        seen: dict = {}
        for idea, kinds in self.families.items():
            for kind in kinds:
                other = seen.setdefault((self.planner_of(idea), kind), idea)
                check(other == idea, f"oracle.families.{idea}", kinds,
                      f"{kind} is in {other} too, sampled by the same planner")  # fmt: skip
        ok = bool(self.sigmas) and all(s >= 0 for s in self.sigmas)
        check(ok, "oracle.sigmas", self.sigmas, "every blur must be >= 0 px")
        ok = bool(self.mixes) and all(0 < m <= 1 for m in self.mixes)
        check(ok, "oracle.mixes", self.mixes, "every mix must be in (0, 1]")
        ok = bool(self.blend_weights) and all(0 <= w <= 1 for w in self.blend_weights)
        check(ok, "oracle.blend_weights", self.blend_weights, "every w must be in [0, 1]")
        check(0 <= self.floor <= 1, "oracle.floor", self.floor, "must be in [0, 1]")
        check(self.radius >= 0, "oracle.radius", self.radius, "must be >= 0 px")
        ok = bool(self.qualities) and all(0 <= q <= 1 for q in self.qualities)
        check(ok, "oracle.qualities", self.qualities, "every q must be in [0, 1]")
        check(self.random_maps >= 2, "oracle.random_maps", self.random_maps, "must be >= 2")
        ok = 0 < self.selection_share < 1
        check(ok, "oracle.selection_share", self.selection_share, "must be in (0, 1)")
        check(self.trials >= 2, "oracle.trials", self.trials, "must be >= 2 (paired CIs)")
        check(isinstance(self.per_cell, bool), "oracle.per_cell", self.per_cell, "true or false")
        check_parts(self.parts, "oracle.parts")


@dataclass
@conf_defaults("regime")
class RegimeGrid:
    """``regime.etas``, ``radius_modes``, ``gamma_factors`` and ``goal_radii``: the cells of
    the planner-regime sweep, for the stages that name them without running the sweep (the
    selection per cell, ``oracle.per_cell``)."""

    etas: list[float]
    radius_modes: list[str]
    gamma_factors: list[float]
    goal_radii: list

    def validate(self) -> None:
        ok = bool(self.etas) and all(e > 0 for e in self.etas)
        check(ok, "regime.etas", self.etas, "every step must be > 0 px (.inf: unlimited)")
        bad = sorted(set(self.radius_modes) - set(REGIME_RADIUS_MODES))
        ok = not bad and bool(self.radius_modes)
        check(ok, "regime.radius_modes", bad, f"known {REGIME_RADIUS_MODES}")
        ok = bool(self.gamma_factors) and all(0 < g < math.inf for g in self.gamma_factors)
        check(ok, "regime.gamma_factors", self.gamma_factors, "every factor must be finite, > 0")
        ok = all(g is None or g > 0 for g in self.goal_radii) and bool(self.goal_radii)
        check(ok, "regime.goal_radii", self.goal_radii, "null, > 0 px or .inf")


@dataclass
@conf_defaults("regime")
class RegimeConfig(RegimeGrid):
    """The ``regime`` section: the planner-regime sweep (its cells and configurations)."""

    configurations: list[str]
    random_maps: int
    trials: int
    parts: list[int]

    def validate(self) -> None:
        super().validate()
        for key in self.configurations:
            try:
                ConfigKey.parse(key)
            except ConfigError as err:
                raise ConfigError(f"invalid regime.configurations entry {key!r}: {err}") from None
        check(self.random_maps >= 1, "regime.random_maps", self.random_maps, "must be >= 1")
        check(self.trials >= 1, "regime.trials", self.trials, "must be >= 1")
        check_parts(self.parts, "regime.parts")
