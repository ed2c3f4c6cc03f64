"""Planner settings: :class:`PlannerConfig`, whose defaults are ``conf/planner/default.yaml``
(the paper's protocol, :meth:`PlannerConfig.paper`; read here, written nowhere else);
:data:`FASTEST`, ``conf/planner/fastest.yaml`` (the Hydra option ``planner=fastest``); and
:data:`USER`, ``conf/planner/user.yaml``: what :func:`vnrrt.planners.plan` and ``vnrrt plan``
use when given no configuration (FASTEST's settings, budgets scaled with the map's free area:
:meth:`PlannerConfig.budgets`). Lengths in pixels, times in seconds.

The files are read with PyYAML by the readers of :mod:`vnrrt.config` (no Hydra here), from
the repository's ``conf/`` or, in an installed wheel, its packaged copy;
``vnrrt.config.section(cfg, "planner", PlannerConfig)`` validates a composed configuration.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

from vnrrt import config
from vnrrt.names import PLANNERS  # noqa: F401  (re-exported: the one list of planners)

REFERENCES = ("astar", "any_angle", "taut")
RADIUS_MODES = ("shrinking", "fixed")


class PlannerConfigError(ValueError):
    """A planner setting is invalid; the message names it."""


@dataclass(frozen=True)
@config.conf_defaults("planner", exact=True, error=PlannerConfigError)
class PlannerConfig:
    """RRT* core, samplers, stop rules and budgets (paper, Background and VertexNet RRT*).
    Lengths in pixels, times in seconds; "ours" marks an option off in the paper's protocol.

    Attributes:
        eta: Steer step.
        radius_mode: ``'shrinking'``: near radius ``min(gamma sqrt(log n / n), eta)``;
            ``'fixed'``: ``fixed_radius``.
        gamma: shrinking-radius constant; ``None`` uses the RRT* bound
            ``2 sqrt(1.5) sqrt(free area / pi)`` of the map (Karaman and Frazzoli).
        gamma_factor: the shrinking radius uses ``gamma_factor x gamma`` (below 1 it falls
            below ``eta`` within a run: the regime sweep's radius rules).
        fixed_radius: near radius in ``'fixed'`` mode.
        goal_radius: a node this close connects to the goal point by a free straight
            segment; ``None``: ``eta``; ``.inf``: any node that sees the goal.
        mix: probability of a heatmap draw in NRRT*/VNRRT*/M-VNRRT* (Algorithm 2: 0.5).
        tau: mask threshold of M-VNRRT* (heatmap values below it get no weight).
        taus: thresholds evaluated for M-VNRRT* (paper: 0.5, 0.9, 0.99).
        eps: stop rule ``optimal``: best cost <= (1 + eps) x reference length.
        reference: the reference length's kind, ``'astar'`` (the paper's), ``'any_angle'``
            or ``'taut'`` (:mod:`vnrrt.planners.reference`).
        min_spacing: a sample this close to its nearest node adds no node (the iteration
            counts), so that a concentrated heatmap (M-VNRRT*) does not pile nodes up in a
            few pixels, slowing every near search and rewire; 0 disables it.
        informed: ours, Informed RRT* (Gammell et al. 2014): once a solution of cost c
            exists, sample inside the ellipse with foci start and goal and major axis c, and
            skip nodes that cannot improve it (:mod:`vnrrt.planners.rrt_star`).
        straight_first: ours, try the straight start-goal segment first: when free it is
            the optimum and the run ends at once.
        refine: ours, share of the iterations, once a solution exists, that are local moves
            on the best path instead of samples (:mod:`vnrrt.planners.refine`).
        pull_parents: ours, a new node's parent is the furthest ancestor of the chosen
            parent that sees it (Theta*'s any-angle parent).
        refine_branches: share of the refinement moves made on the branch of a random tree
            node that could still lead to a better solution, rather than on the best path.
        gap_share: ours, share of the samples drawn from the narrow-passage cells of width
            at most ``gap_width`` cells (:mod:`vnrrt.planners.gaps`), found by each run
            (inside its timed region) after ``gap_after`` iterations.
        gap_width: widest passage (cells) whose cells the gap sampler draws.
        gap_after: iterations before the gap sampler's first draw.
        max_iterations, max_seconds: budgets; hitting one is a recorded failure. With the
            budget rule on, the floors of the map's budgets (:meth:`budgets`).
        iterations_per_free_cell, seconds_per_free_cell: the budget rule (:meth:`budgets`);
            None: the budget is fixed, as in the paper's protocol.
        trace_capacity: most points kept in the sparse cost-versus-iteration trace.

    Frozen: :meth:`replace` validates the copy, so a config that passed :meth:`validate`
    stays valid (the check is remembered).
    """

    eta: float
    radius_mode: str
    gamma: float | None
    gamma_factor: float
    fixed_radius: float
    goal_radius: float | None
    mix: float
    tau: float
    taus: list[float]
    eps: float
    reference: str
    min_spacing: float
    informed: bool
    straight_first: bool
    refine: float
    pull_parents: bool
    refine_branches: float
    gap_share: float
    gap_width: int
    gap_after: int
    max_iterations: int
    max_seconds: float
    iterations_per_free_cell: float | None
    seconds_per_free_cell: float | None
    trace_capacity: int

    @classmethod
    def paper(cls) -> PlannerConfig:
        """The paper's protocol: ``conf/planner/default.yaml`` (the study's ``planner=default``),
        fixed budgets."""
        return cls()

    @classmethod
    def named(cls, option: str) -> PlannerConfig:
        """The validated settings of ``conf/planner/<option>.yaml`` as Hydra composes the
        option (``default``, ``fastest``, ``user``); :class:`PlannerConfigError` names the file
        and an unknown key or invalid value, :class:`vnrrt.config.ConfigError` a missing file."""
        values = config.conf_file("planner", option)
        try:
            return cls().replace(**values)
        except PlannerConfigError as e:
            raise PlannerConfigError(f"conf/planner/{option}.yaml: {e}") from None

    @property
    def scales_budgets(self) -> bool:
        """Whether a budget grows with the map's free cells (:meth:`budgets`)."""
        return self.iterations_per_free_cell is not None or self.seconds_per_free_cell is not None

    def budgets(self, free_cells: int) -> tuple[int, float]:
        """``(max_iterations, max_seconds)`` of a run on a map of ``free_cells`` free cells:
        the fixed budgets, or with the budget rule ``max(max_iterations,
        ceil(iterations_per_free_cell x free_cells))`` and ``max(max_seconds,
        seconds_per_free_cell x free_cells)``."""
        iterations, seconds = int(self.max_iterations), float(self.max_seconds)
        if self.iterations_per_free_cell is not None:
            iterations = max(iterations, math.ceil(self.iterations_per_free_cell * free_cells))
        if self.seconds_per_free_cell is not None:
            seconds = max(seconds, self.seconds_per_free_cell * free_cells)
        return iterations, seconds

    def validate(self) -> None:
        """Raise :class:`PlannerConfigError` naming the first invalid value."""
        if self.__dict__.get("_valid"):
            return
        for name in ("fixed_radius", "max_seconds"):
            v = getattr(self, name)
            self._check(name, _finite(v) and v > 0, "> 0")
        ok = _number(self.eta) and self.eta > 0
        self._check("eta", ok, "> 0 (.inf: steer straight to the sample)")
        ok = _finite(self.gamma_factor) and self.gamma_factor > 0
        self._check("gamma_factor", ok, "finite and > 0")
        self._check(
            "gamma", self.gamma is None or (_finite(self.gamma) and self.gamma > 0), "null or > 0"
        )
        g = self.goal_radius
        self._check(
            "goal_radius", g is None or g == math.inf or (_finite(g) and g > 0), "null, > 0 or .inf"
        )
        for name in ("refine", "refine_branches", "gap_share"):
            v = getattr(self, name)
            self._check(name, _finite(v) and 0.0 <= v <= 1.0, "in [0, 1]")
        for name in ("informed", "straight_first", "pull_parents"):
            self._check(name, isinstance(getattr(self, name), bool), "true or false")
        self._check("radius_mode", self.radius_mode in RADIUS_MODES, f"one of {RADIUS_MODES}")
        self._check("reference", self.reference in REFERENCES, f"one of {REFERENCES}")
        self._check("mix", _finite(self.mix) and 0.0 <= self.mix <= 1.0, "in [0, 1]")
        self._check("eps", _finite(self.eps) and self.eps >= 0, ">= 0")
        ok = _finite(self.min_spacing) and 0 <= self.min_spacing < self.eta
        self._check("min_spacing", ok, ">= 0 and < eta")
        ok = _integer(self.max_iterations) and self.max_iterations >= 1
        self._check("max_iterations", ok, "an integer >= 1")
        ok = _integer(self.gap_width) and 1 <= self.gap_width <= 2**31
        self._check("gap_width", ok, "an integer in [1, 2^31]")
        ok = _integer(self.gap_after) and 0 <= self.gap_after <= 2**62
        self._check("gap_after", ok, "an integer in [0, 2^62]")
        ok = _integer(self.trace_capacity) and self.trace_capacity >= 2
        self._check("trace_capacity", ok, "an integer >= 2")
        for name in ("iterations_per_free_cell", "seconds_per_free_cell"):
            v = getattr(self, name)
            self._check(name, v is None or (_finite(v) and v >= 0), "null or a number >= 0")
        self._check("tau", _finite(self.tau), "finite")
        self._check("taus", all(_finite(t) for t in self.taus), "finite values")
        object.__setattr__(self, "_valid", True)  # not a field: eq, repr and replace ignore it

    def _check(self, name: str, ok: bool, why: str) -> None:
        if not ok:
            value = getattr(self, name)
            raise PlannerConfigError(f"invalid planner setting {name}={value!r}: must be {why}")

    def replace(self, **changes) -> PlannerConfig:
        """A validated copy with ``changes`` applied; unknown names raise an error."""
        known = {f.name for f in dataclasses.fields(self)}
        unknown = sorted(set(changes) - known)
        if unknown:
            raise PlannerConfigError(
                f"unknown planner setting(s) {unknown}; known: {sorted(known)}"
            )
        new = dataclasses.replace(self, **changes)
        new.validate()
        return new


def _integer(v) -> bool:
    return isinstance(v, int) and not isinstance(v, bool)


def _number(v) -> bool:
    return isinstance(v, int | float) and not isinstance(v, bool) and not math.isnan(v)


def _finite(v) -> bool:
    return isinstance(v, int | float) and not isinstance(v, bool) and math.isfinite(v)


FASTEST = PlannerConfig.named("fastest")  # our fastest settings, any planner, fixed budgets
USER = PlannerConfig.named("user")  # plan()'s and `vnrrt plan`'s: FASTEST, scaled budgets
