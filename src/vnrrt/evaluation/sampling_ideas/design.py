"""What the sampling-ideas study runs: the oracle study's configurations and the planner-regime
sweep's cells (settings in :mod:`vnrrt.evaluation.config`: ``oracle``, ``regime``).

* **Oracle study** (stage ``oracle@<k>``): on the first ``oracle.random_maps`` random
  instances, the protocol's configurations (``eval.planners`` with their ``eval.sources``,
  and informed ones when ``eval.informed``); every oracle of ``oracle.kinds``
  (:mod:`vnrrt.evaluation.sources`) through the heatmap sampler (NRRT* for path oracles,
  VNRRT* for the others) and, for vertex oracles, the masked sampler at every tau; and the
  heatmap-quality curve: the path oracle (NRRT*), the vertex oracle (VNRRT*) and the masked
  vertex oracle (M-VNRRT* at every tau) mixed with a uniform map at each signal fraction
  ``oracle.qualities``. All stop rules, paired seeds, one table.
* **Regime sweep** (stage ``regime@<k>``): the configurations of ``regime.configurations``
  in every cell of ``regime.etas x regime.radius_modes x regime.goal_radii`` (the planner
  settings the paper does not give), to within ``planner.eps`` of the A* length and of the
  exact optimum.
"""

from __future__ import annotations

from vnrrt.evaluation.config import Configurations, OracleConfig, RegimeConfig
from vnrrt.evaluation.keys import ConfigKey
from vnrrt.evaluation.protocol import STOPS, configurations
from vnrrt.evaluation.sources import source_name

QUALITY_IDEAS = ("oracle_path", "oracle_vertex")  # the oracles of the quality curve


def oracle_keys(
    oc: OracleConfig, ev: Configurations, taus: list[float], tau: float
) -> list[ConfigKey]:
    """The oracle study's configurations (module doc), each once, in a fixed order; ``taus``
    every M-VNRRT* threshold, ``tau`` the claims' (``planner.tau``)."""
    keys = configurations(ev, taus, tau)  # RRT* and the trained networks, as configured
    for kind in oc.kinds:
        keys += idea_keys(kind, taus, 1.0)
    for q in oc.qualities:
        if q != 1.0:
            for kind in QUALITY_IDEAS:
                keys += idea_keys(kind, taus, q)
    return list(dict.fromkeys(keys))


def idea_keys(kind: str, taus: list[float], q: float) -> list[ConfigKey]:
    """How an oracle is sampled: a path oracle through the heatmap sampler (NRRT*), the
    others through the heatmap sampler (VNRRT*) and the masked one at every tau (M-VNRRT*)."""
    source = source_name(kind, q)
    if "path" in kind:
        return [ConfigKey("nrrt_star").with_source(source)]
    masked = [ConfigKey("m_vnrrt_star", t).with_source(source) for t in sorted(set(taus))]
    return [ConfigKey("vnrrt_star").with_source(source), *masked]


def oracle_counts(oc: OracleConfig) -> dict[tuple[str, str], int]:
    """Trials per random instance for every stop rule."""
    return {("random", stop): oc.trials for stop in STOPS}


def regime_keys(rc: RegimeConfig, sources: dict[str, str]) -> list[ConfigKey]:
    """``regime.configurations`` as keys, protocol sources resolved by ``sources``
    (``eval.sources``)."""
    return [ConfigKey.parse(k, sources) for k in rc.configurations]


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
