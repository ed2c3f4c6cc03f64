"""The registry of planners and the display names shared by the reports and the figures:
planners, map sets and stop rules. Values a name depends on (the stop tolerance, the CI
level) are arguments, taken from the run's config. A leaf module (no imports), so that any
stage may use it without depending on the planners' code."""

from __future__ import annotations

PLANNER_NAMES = {  # the planners, in the paper's order, with their display names
    "rrt_star": "RRT*",
    "nrrt_star": "NRRT*",
    "vnrrt_star": "VNRRT*",
    "m_vnrrt_star": "M-VNRRT*",
}
PLANNERS = tuple(PLANNER_NAMES)
MAP_SETS = ("map_1", "map_2", "map_3", "map_4", "map_5", "random")
MAP_SET_NAMES = dict(zip(MAP_SETS, [f"Map {i}" for i in range(1, 6)] + ["Random maps"]))
REFERENCE_NAMES = {"optimal": "A*", "optimal_any_angle": "the exact optimum"}


def percent(eps: float) -> str:
    """A tolerance as a percentage: ``0.01`` -> ``1%``, ``0.005`` -> ``0.5%``."""
    return f"{100 * eps:g}%"


def stop_name(stop: str, eps: float) -> str:
    """``initial solution``, ``within 1% of A*`` (eps 0.01), ``within 5% of the exact
    optimum`` (eps 0.05)."""
    if stop == "initial":
        return "initial solution"
    return f"within {percent(eps)} of {REFERENCE_NAMES[stop]}"


def stop_title(stop: str, eps: float) -> str:
    """The longer form of :func:`stop_name` for section titles."""
    if stop == "initial":
        return "initial solution"
    if stop == "optimal":
        return f"cost <= {1 + eps:g} x A* length (the paper's optimal solution, eps {eps:g})"
    return f"cost <= {1 + eps:g} x exact continuous optimum (stricter; ours, eps {eps:g})"


def stop_slug(stop: str, eps: float) -> str:
    """A stop rule as a part of an MLflow metric name: ``initial_solution``,
    ``within_1pct_of_astar``, ``within_0.5pct_of_exact_optimum``."""
    if stop == "initial":
        return "initial_solution"
    reference = "astar" if stop == "optimal" else "exact_optimum"
    return f"within_{percent(eps).replace('%', 'pct')}_of_{reference}"


def map_set_slug(map_set: str) -> str:
    """A map set as a part of an MLflow metric name: ``random_maps``, ``map_3``."""
    return "random_maps" if map_set == "random" else map_set


def level_name(level: float) -> str:
    """A confidence level as text: ``0.95`` -> ``95%``."""
    return f"{100 * level:g}%"


def map_set_title(map_set: str, name: str | None = None) -> str:
    """``Map 3: narrow passage`` (with the named map's name) or ``Random maps``."""
    title = MAP_SET_NAMES.get(map_set, map_set)
    return f"{title}: {name.replace('_', ' ')}" if name else title


def mask_taus(taus, tau: float | None) -> list[float]:
    """The M-VNRRT* thresholds a run evaluates: ``planner.taus`` and ``planner.tau`` (None:
    ``taus`` alone), sorted, each once."""
    return sorted({float(t) for t in (*taus, *([] if tau is None else [tau]))})
