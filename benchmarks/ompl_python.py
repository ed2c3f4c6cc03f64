"""OMPL through its Python bindings (PyPI ``ompl``, nanobind) as a planner baseline: a Python
validity checker called for every state, so every check OMPL makes is a Python call."""

from __future__ import annotations

import math
import time

import numpy as np

PLANNERS = ("RRTstar", "InformedRRTstar", "BITstar")


def quiet(seed: int) -> None:
    """Warnings only, and OMPL's RNG seeded (once per process)."""
    from ompl import util as ou

    ou.setLogLevel(ou.LogLevel.LOG_WARN)
    ou.RNG.setSeed(seed)


def solve(g: np.ndarray, start, goal, bound: float, limit: float, name: str,
          step: float = 0.0) -> dict:  # fmt: skip
    """OMPL planner ``name`` on RealVectorStateSpace(2) over ``[0, W] x [0, H]`` (motions
    checked every 0.5 px), stopped at cost ``bound`` or ``limit`` s; ``step``: the range of
    the RRT* planners (0: OMPL's default). Returns ``{"first": s, "stop": s, "path": (K, 2)}``
    (NaN: not reached; path None without an exact solution)."""
    from ompl import base as ob
    from ompl import geometric as og

    h, w = g.shape
    space = ob.RealVectorStateSpace(2)
    box = ob.RealVectorBounds(2)
    box.setLow(0, 0.0), box.setHigh(0, float(w)), box.setLow(1, 0.0), box.setHigh(1, float(h))
    space.setBounds(box)
    si = ob.SpaceInformation(space)
    grid = g.tolist()
    si.setStateValidityChecker(lambda s: not grid[int(s[1])][int(s[0])])
    si.setStateValidityCheckingResolution(0.5 / si.getMaximumExtent())
    si.setup()
    s, e = space.allocState(), space.allocState()
    s[0], s[1], e[0], e[1] = *start, *goal
    pdef = ob.ProblemDefinition(si)
    pdef.setStartAndGoalStates(s, e, 1e-6)
    objective = ob.PathLengthOptimizationObjective(si)
    objective.setCostThreshold(ob.Cost(bound))
    pdef.setOptimizationObjective(objective)
    planner = getattr(og, name)(si)
    if step > 0:
        planner.setRange(step)
    planner.setProblemDefinition(pdef)
    planner.setup()
    times, t0 = {"first": math.nan, "stop": math.nan}, time.perf_counter()

    def stop() -> bool:
        now, c = time.perf_counter() - t0, planner.bestCost().value()
        if c < math.inf and math.isnan(times["first"]):
            times["first"] = now
        if c <= bound and math.isnan(times["stop"]):
            times["stop"] = now
        return now >= limit or not math.isnan(times["stop"])

    planner.solve(ob.PlannerTerminationCondition(stop))
    stop()  # OMPL returns as soon as its cost threshold is met, before asking stop() again
    ok = pdef.hasExactSolution()
    path = np.array([[st[0], st[1]] for st in pdef.getSolutionPath().getStates()]) if ok else None
    return {**times, "path": path}
