"""Benchmark: this package's planners against OMPL's best on occupancy grids.

In one process, on the same maps (the five named maps, crafted traps, random test maps of
the data generator) and start/goal pairs: our best configuration (informed RRT*, the
straight segment tried first, the goal joined by any node that sees it, Steer step 20 px),
our paper-setting RRT* (step 10 px), and OMPL's RRTstar, InformedRRTstar and BITstar at
their default settings and, for the two with a step, at our step ("matched"). Every run
records, in seconds from the planner's start, the time to its first solution and to a cost
within 1% of the exact continuous optimum (:func:`vnrrt.planners.any_angle_path`); a run
stops there or at ``--time-limit`` (then it counts as the limit: medians marked ">=" are
lower bounds). Per map the median over trials, and the ratio of the best OMPL planner's
median to ours; overall the median over maps. OMPL checks states with a Python validity
checker every 0.5 px along motions, so its paths may clip obstacle corners: every final
path is checked with our exact segment test and the clipping paths are counted (ours: by
construction none).

    python benchmarks/bench_planners.py [--random 12] [--trials 3] [--time-limit 2]
"""

from __future__ import annotations

import argparse
import math
import os
import sys
import time

import numpy as np

from vnrrt.maps.config import DataConfig
from vnrrt.maps.generate import generate_map, largest_free_region, map_rng
from vnrrt.maps.named import NAMES, named_map
from vnrrt.planners import any_angle_path, path_free, plan, warmup
from vnrrt.planners.collision import point_free

ETA, BEST_ETA = 10.0, 20.0
OURS = {
    "ours-best": dict(informed=True, straight_first=True, goal_radius=math.inf, eta=BEST_ETA),
    "ours-rrt*": dict(eta=ETA),
}
OMPL = ("RRTstar", "InformedRRTstar", "BITstar")


# --- maps ------------------------------------------------------------------------------------


def _walls(rng: np.random.Generator, size: int) -> np.ndarray:
    g = np.zeros((size, size), np.uint8)
    for i, x in enumerate(np.linspace(0, size, rng.integers(2, 4) + 2)[1:-1].astype(int)):
        gap = rng.integers(3, 7)  # a narrow gap, 3..6 px
        y = rng.integers(10, size - 10 - gap)
        g[:, x : x + 3] = 1
        g[y : y + gap, x : x + 3] = 0
        if i % 2:
            y2 = (y + size // 2) % (size - 20) + 5
            g[y2 : y2 + 8, x : x + 3] = 0
    return g


def _bug_trap(size: int) -> np.ndarray:
    """A C around the start at the centre, open to the left, the goal to the right."""
    g = np.zeros((size, size), np.uint8)
    g[60:140, 136:140] = 1  # the wall between start and goal
    g[60:64, 60:140] = 1
    g[136:140, 60:140] = 1
    return g


def _far_pair(rng, g, min_dist):
    free = np.argwhere(g == 0)[:, ::-1] + 0.5
    while True:
        s, e = free[rng.integers(len(free), size=2)]
        if math.dist(s, e) >= min_dist and point_free(g, s) and point_free(g, e):
            return tuple(s), tuple(e)


def make_instances(n_random: int, seed: int, size: int = 200) -> list[tuple]:
    """``(name, grid, start, goal)``: the named maps, crafted traps, random test maps."""
    out = []
    for name in NAMES:
        fm = named_map(name, size)
        out.append((name, fm.grid, tuple(fm.starts[0] + 0.5), tuple(fm.goals[0] + 0.5)))
    rng = np.random.default_rng(seed)
    for k in range(3):
        g = _walls(rng, size)
        out.append((f"walls{k}", g, (5.5, size / 2 + 0.5), (size - 5.5, size / 2 + 0.5)))
    out.append(("bug_trap", _bug_trap(size), (100.5, 100.5), (190.5, 100.5)))
    empty = np.zeros((size, size), np.uint8)
    out.append(("empty", empty, (5.5, 5.5), (size - 5.5, size - 5.5)))
    for i in range(n_random):
        fm = generate_map(map_rng(seed + 1, i), DataConfig(size=size))
        outside = (~largest_free_region(fm.grid)).astype(np.uint8)  # start/goal connected
        s, e = _far_pair(rng, outside, 0.4 * size)
        out.append((f"random{i}", fm.grid, s, e))
    return out


# --- planners ----------------------------------------------------------------------------------


def run_ours(g, start, goal, bound, seed, limit, settings) -> dict:
    r = plan(
        g,
        start,
        goal,
        "rrt_star",
        stop="optimal",
        reference_length=bound / 1.01,
        seed=seed,
        max_seconds=limit,
        **settings,
    )
    times = {"first": r.time_to_first}
    if r.success:
        times["optimal"] = r.time_to_stop
    clipped = len(r.path) > 0 and not path_free(g, r.path)
    return {"times": {k: v for k, v in times.items() if not math.isnan(v)}, "clipped": clipped}


def run_ompl(g, start, goal, bound, limit, name, matched) -> dict:
    """OMPL planner ``name`` on RealVectorStateSpace(2) with a Python point validity checker
    (motions checked every 0.5 px); a termination callback records the first-solution and
    1%-of-optimum times."""
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
    if matched and hasattr(planner, "setRange"):
        planner.setRange(ETA)
    planner.setProblemDefinition(pdef)
    planner.setup()
    times, t0 = {}, time.perf_counter()

    def stop() -> bool:
        now, c = time.perf_counter() - t0, planner.bestCost().value()
        if c < math.inf and "first" not in times:
            times["first"] = now
        if c <= bound and "optimal" not in times:
            times["optimal"] = now
        return now >= limit or "optimal" in times

    planner.solve(ob.PlannerTerminationCondition(stop))
    stop()  # OMPL returns as soon as its cost threshold is met, before asking stop() again
    ok = pdef.hasExactSolution()
    path = np.array([[st[0], st[1]] for st in pdef.getSolutionPath().getStates()]) if ok else None
    return {"times": times, "clipped": path is not None and not path_free(g, path)}


# --- the report ----------------------------------------------------------------------------------


def median_time(runs: list[dict], key: str, limit: float) -> tuple[float, bool]:
    """Median seconds to ``key`` over trials (a miss counts as ``limit``), and whether it
    is a lower bound (half or more missed)."""
    vals = np.array([r["times"].get(key, math.inf) for r in runs])
    return float(np.median(np.minimum(vals, limit))), 2 * np.isinf(vals).sum() >= len(vals)


def report(per_map: dict, names: list[str], limit: float) -> None:
    omplers = [n for n in names if n.startswith("ompl")]
    for key, label in (("first", "first solution"), ("optimal", "<= 1.01 x exact optimum")):
        print(f"\nmedian ms to the {label}, per map (ratio = best OMPL / ours-best)")
        wide = max(map(len, names)) + 2
        print(f"{'map':<16}" + "".join(f"{n:>{wide}}" for n in names) + f"{'ratio':>9}")
        ratios = []
        for name, runs in per_map.items():
            meds = {n: median_time(runs[n], key, limit) for n in names}
            cells = "".join(
                f"{('>=' if c else '') + f'{1e3 * m:.3g}':>{wide}}" for m, c in meds.values()
            )
            best = min(meds[n][0] for n in omplers)
            ratio = best / max(meds["ours-best"][0], 1e-9)
            ratios.append(ratio)
            print(f"{name:<16}{cells}{ratio:>9.1f}")
        overall = {
            n: np.median([median_time(per_map[m][n], key, limit)[0] for m in per_map])
            for n in names
        }
        print(f"{'median of maps':<16}" + "".join(f"{1e3 * overall[n]:>{wide}.3g}" for n in names))
        best = min(overall[n] for n in omplers) / overall["ours-best"]
        print(
            f"ours-best vs the best OMPL planner: median over maps {best:.1f}x; per map: "
            f"median ratio {np.median(ratios):.1f}x, worst {min(ratios):.2f}x"
        )
    for n in names:
        runs = [r for per in per_map.values() for r in per[n]]
        print(
            f"{n}: final paths clipping an obstacle (exact test): "
            f"{sum(r['clipped'] for r in runs)}/{len(runs)}"
        )


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--random", type=int, default=12, help="random test maps (beside 10 fixed)")
    ap.add_argument("--trials", type=int, default=3, help="runs per map and planner")
    ap.add_argument("--time-limit", type=float, default=2.0, help="seconds per run")
    ap.add_argument("--seed", type=int, default=0)
    args = ap.parse_args(argv)
    from ompl import util as ou

    ou.setLogLevel(ou.LogLevel.LOG_WARN)
    ou.RNG.setSeed(args.seed + 1)
    warmup()  # JIT compilation (or cache load) outside every timing
    names = [
        *OURS,
        *(f"ompl-{n}" for n in OMPL),
        "ompl-RRTstar-matched",
        "ompl-InformedRRTstar-matched",
    ]
    per_map = {}
    for m, (name, g, s, e) in enumerate(make_instances(args.random, args.seed)):
        bound = 1.01 * any_angle_path(g, s, e)[1]
        runs = {n: [] for n in names}
        for k in range(args.trials):
            seed = (args.seed, m, k)
            for label, settings in OURS.items():
                runs[label].append(run_ours(g, s, e, bound, seed, args.time_limit, settings))
            for n in names[len(OURS) :]:
                algo = n.removeprefix("ompl-").removesuffix("-matched")
                runs[n].append(
                    run_ompl(g, s, e, bound, args.time_limit, algo, n.endswith("matched"))
                )
        per_map[name] = runs
        print(f"{name}: exact optimum {bound / 1.01:.1f} px", flush=True)
    report(per_map, names, args.time_limit)


if __name__ == "__main__":
    main()
    sys.stdout.flush()
    sys.stderr.flush()
    os._exit(0)  # skip interpreter teardown: OMPL's nanobind bindings print leak warnings
