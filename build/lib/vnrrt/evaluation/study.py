"""What each sampling idea can give: the oracle study and the planner-regime sweep.

* **Oracle study** (stage ``oracle@<k>``): on the first ``oracle.random_maps`` random
  instances, RRT*; the trained networks' configurations; every oracle kind
  (:mod:`vnrrt.evaluation.oracle`) through the heatmap sampler (NRRT* for path oracles,
  VNRRT* for the others) and, for vertex oracles, the masked sampler at every tau; and the
  heatmap-quality curve: the path oracle (NRRT*), the vertex oracle (VNRRT*) and the masked
  vertex oracle (M-VNRRT* at every tau) mixed with a uniform map at each signal fraction q.
  All stop rules, paired seeds, one table.
* **Regime sweep** (stage ``regime@<k>``): the configurations of ``regime.configurations``
  in every cell of ``regime.etas x regime.radius_modes x regime.goal_radii`` (the planner
  settings the paper does not give), to within 1% of the A* length and of the exact optimum
  (1.02 read off the same runs).
"""

from __future__ import annotations

from dataclasses import dataclass, field

from vnrrt.config import ConfigError, check, check_parts
from vnrrt.evaluation.oracle import KINDS, source_name
from vnrrt.evaluation.protocol import (
    STOPS,
    PlannerSpec,
    parse_key,
    planner_specs,
    with_source,
)

RADIUS_MODES = ("shrinking", "fixed1", "fixed2")


@dataclass
class OracleConfig:
    """The ``oracle`` config section (``conf/oracle/default.yaml``)."""

    kinds: list[str] = field(default_factory=lambda: list(KINDS))
    sigma: float = 1.0
    floor: float = 0.0
    radius: float = 3.0
    qualities: list[float] = field(default_factory=lambda: [1.0, 0.5, 0.2, 0.1, 0.05, 0.02, 0.0])
    random_maps: int = 1000
    trials: int = 1
    parts: list[int] = field(default_factory=lambda: [0])

    def validate(self) -> None:
        unknown = sorted(set(self.kinds) - set(KINDS))
        check(not unknown, "oracle.kinds", self.kinds, f"known: {KINDS}")
        check(self.sigma >= 0, "oracle.sigma", self.sigma, "must be >= 0 px")
        check(0 <= self.floor <= 1, "oracle.floor", self.floor, "must be in [0, 1]")
        check(self.radius >= 0, "oracle.radius", self.radius, "must be >= 0 px")
        ok = bool(self.qualities) and all(0 <= q <= 1 for q in self.qualities)
        check(ok, "oracle.qualities", self.qualities, "every q must be in [0, 1]")
        check(self.random_maps >= 1, "oracle.random_maps", self.random_maps, "must be >= 1")
        check(self.trials >= 1, "oracle.trials", self.trials, "must be >= 1")
        check_parts(self.parts, "oracle.parts")


@dataclass
class RegimeConfig:
    """The ``regime`` config section (``conf/regime/default.yaml``)."""

    etas: list[float] = field(default_factory=lambda: [3.0, 5.0, 10.0, 20.0, 40.0])
    radius_modes: list[str] = field(default_factory=lambda: list(RADIUS_MODES))
    goal_radii: list = field(default_factory=lambda: [None, 2.0])
    configurations: list[str] = field(default_factory=lambda: ["rrt_star"])
    random_maps: int = 1000
    parts: list[int] = field(default_factory=lambda: [0])

    def validate(self) -> None:
        ok = bool(self.etas) and all(e > 0 for e in self.etas)
        check(ok, "regime.etas", self.etas, "every step must be > 0 px")
        bad = sorted(set(self.radius_modes) - set(RADIUS_MODES))
        check(not bad and self.radius_modes, "regime.radius_modes", bad, f"known {RADIUS_MODES}")
        ok = all(g is None or g > 0 for g in self.goal_radii) and bool(self.goal_radii)
        check(ok, "regime.goal_radii", self.goal_radii, "null or > 0 px")
        for key in self.configurations:
            try:
                parse_key(key, {"nrrt_star": "n", "vnrrt_star": "n", "m_vnrrt_star": "n"})
            except (ConfigError, ValueError) as err:
                raise ConfigError(f"invalid regime.configurations entry {key!r}: {err}") from None
        check(self.random_maps >= 1, "regime.random_maps", self.random_maps, "must be >= 1")
        check_parts(self.parts, "regime.parts")


def oracle_specs(
    oc: OracleConfig, taus: list[float], networks: dict[str, str]
) -> list[PlannerSpec]:
    """The oracle study's configurations (module doc); ``networks`` maps the trained
    configurations' planners to their networks (``eval.sources``)."""
    from vnrrt.evaluation.config import EvalConfig

    taus = sorted(set(taus))
    specs = planner_specs(EvalConfig(sources=dict(networks)), taus)  # RRT* and the networks
    for kind in oc.kinds:
        specs += idea_specs(kind, taus, 1.0)
    for q in oc.qualities:
        if q != 1.0:
            for kind in ("oracle_path", "oracle_vertex"):
                specs += idea_specs(kind, taus, q)
    seen, out = set(), []
    for spec in specs:
        if spec.key not in seen:
            seen.add(spec.key)
            out.append(spec)
    return out


def idea_specs(kind: str, taus: list[float], q: float) -> list[PlannerSpec]:
    """How an oracle is sampled: a path oracle through the heatmap sampler (NRRT*), the
    others through the heatmap sampler (VNRRT*) and the masked one at every tau (M-VNRRT*)."""
    source = source_name(kind, q)
    if "path" in kind:
        return [with_source(PlannerSpec("nrrt_star", None, source), source)]
    masked = [with_source(PlannerSpec("m_vnrrt_star", t, source), source) for t in taus]
    return [with_source(PlannerSpec("vnrrt_star", None, source), source), *masked]


def oracle_counts(oc: OracleConfig) -> dict[tuple[str, str], int]:
    """Trials per random instance for every stop rule."""
    return {("random", stop): oc.trials for stop in STOPS}


def regime_cells(rc: RegimeConfig) -> dict[str, dict]:
    """``{label: planner overrides}`` of every cell, e.g. ``eta=5 radius=fixed1 goal=eta``:
    ``{"eta": 5.0, "radius_mode": "fixed", "fixed_radius": 5.0, "goal_radius": None}``."""
    cells = {}
    for eta in rc.etas:
        for mode in rc.radius_modes:
            for goal in rc.goal_radii:
                over = {"eta": float(eta), "goal_radius": None if goal is None else float(goal)}
                if mode == "shrinking":
                    over["radius_mode"] = "shrinking"
                else:
                    over["radius_mode"] = "fixed"
                    over["fixed_radius"] = float(eta) * int(mode[len("fixed") :])
                goal_label = "eta" if goal is None else f"{goal:g}"
                cells[f"eta={eta:g} radius={mode} goal={goal_label}"] = over
    return cells


def regime_counts() -> dict[tuple[str, str], int]:
    """One trial per random instance, to the A* length and to the exact optimum."""
    return {("random", "optimal"): 1, ("random", "optimal_any_angle"): 1}
