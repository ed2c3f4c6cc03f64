"""Display names and the paper's order of planner configurations and map sets (shared by
the report and the figures)."""

from __future__ import annotations

PLANNER_ORDER = ("rrt_star", "nrrt_star", "vnrrt_star", "m_vnrrt_star")
PLANNER_NAMES = {
    "rrt_star": "RRT*",
    "nrrt_star": "NRRT*",
    "vnrrt_star": "VNRRT*",
    "m_vnrrt_star": "M-VNRRT*",
}
MAP_SET_NAMES = {
    "map_1": "Map 1",
    "map_2": "Map 2",
    "map_3": "Map 3",
    "map_4": "Map 4",
    "map_5": "Map 5",
    "random": "Random maps",
}
STOP_NAMES = {
    "initial": "initial solution",
    "optimal": "within 1% of A*",
    "optimal_any_angle": "within 1% of the exact optimum",
}


INFORMED = "+informed"


def display_name(key: str) -> str:
    """``m_vnrrt_star@0.5`` -> ``M-VNRRT* τ=0.5``; a heatmap source suffix ``[src]`` is kept;
    ``+informed`` -> ``informed ...`` (``rrt_star+informed`` -> ``Informed RRT*``)."""
    if key.endswith(INFORMED):
        name = display_name(key.removesuffix(INFORMED))
        return "Informed RRT*" if name == "RRT*" else f"informed {name}"
    base, _, source = key.partition("[")
    planner, _, tau = base.partition("@")
    name = PLANNER_NAMES.get(planner, planner) + (f" τ={tau}" if tau else "")
    return name + (f" [{source.rstrip(']')}]" if source else "")


def sort_keys(keys) -> list[str]:
    """Configuration keys in the paper's order (planner, then tau, then source)."""

    def rank(key: str):
        informed = key.endswith(INFORMED)
        base, _, source = key.removesuffix(INFORMED).partition("[")
        planner, _, tau = base.partition("@")
        order = PLANNER_ORDER.index(planner) if planner in PLANNER_ORDER else len(PLANNER_ORDER)
        return (informed, order, float(tau) if tau else -1.0, source)

    return sorted(keys, key=rank)


def map_set_title(map_set: str, name: str | None = None) -> str:
    """``Map 3: narrow passage`` (with the named map's name) or ``Random maps``."""
    title = MAP_SET_NAMES.get(map_set, map_set)
    return f"{title}: {name.replace('_', ' ')}" if name else title
