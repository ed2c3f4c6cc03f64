"""Benchmark: this package's numba RRT* vs a pure-Python RRT* vs OMPL's RRTstar.

All three run in one process on the same seeded 200x200 maps (random rectangles and
circles, and walls with narrow gaps) and the same start/goal pairs, with the same step
(eta = 10 px). For each run we record, in seconds from the planner's start, the time to
the first solution, to a cost within 1% of the 8-connected A* length, and to within 1%
of the any-angle (taut A*) length; a run stops at the last or at ``--time-limit``.
Medians are over all (map, trial) runs; a run that never reached a bound counts as the
time limit, so a median marked ">=" is a lower bound. Every final OMPL path is checked
with our exact segment test (:mod:`vnrrt.planners.collision`); OMPL itself checks points
every 0.5 px along motions, so its paths may clip obstacle corners.

    python benchmarks/bench_planners.py [--maps 20] [--trials 1] [--time-limit 5]
"""

from __future__ import annotations

import argparse
import math
import os
import sys
import time

import numpy as np

from vnrrt.planners import any_angle_length, astar_length, path_free, plan, warmup
from vnrrt.planners.collision import point_free

ETA = 10.0
KEYS = ("first", "astar", "any_angle")


# --- maps ----------------------------------------------------------------------------------


def _shapes_map(rng: np.random.Generator, size: int) -> np.ndarray:
    g = np.zeros((size, size), np.uint8)
    yy, xx = np.mgrid[:size, :size]
    for _ in range(rng.integers(8, 17)):
        x, y = rng.integers(0, size, 2)
        if rng.random() < 0.5:
            w, h = rng.integers(8, 40, 2)
            g[y : y + h, x : x + w] = 1
        else:
            g[(xx - x) ** 2 + (yy - y) ** 2 <= rng.integers(5, 20) ** 2] = 1
    return g


def _walls_map(rng: np.random.Generator, size: int) -> np.ndarray:
    g = np.zeros((size, size), np.uint8)
    for i, x in enumerate(np.linspace(0, size, rng.integers(2, 4) + 2)[1:-1].astype(int)):
        gap = rng.integers(3, 7)  # a narrow gap, 3..6 px
        y = rng.integers(10, size - 10 - gap)
        g[:, x : x + 3] = 1
        g[y : y + gap, x : x + 3] = 0
        if i % 2:  # some walls get a second, wider gap
            y2 = (y + size // 2) % (size - 20) + 5
            g[y2 : y2 + 8, x : x + 3] = 0
    return g


def make_instances(n: int, seed: int, size: int = 200) -> list[tuple]:
    """``n`` (grid, start, goal) with connected, distant cell-centre endpoints."""
    rng = np.random.default_rng(seed)
    out = []
    while len(out) < n:
        g = _walls_map(rng, size) if len(out) % 3 == 2 else _shapes_map(rng, size)
        free = np.argwhere(g == 0)[:, ::-1] + 0.5
        for _ in range(20):
            s, e = free[rng.integers(len(free), size=2)]
            if math.dist(s, e) < 0.6 * size or not (point_free(g, s) and point_free(g, e)):
                continue
            try:
                astar_length(g, s, e)
            except ValueError:
                continue
            out.append((g, tuple(s), tuple(e)))
            break
    return out


# --- pure-Python RRT* ------------------------------------------------------------------------


def py_segment_free(g, x0, y0, x1, y1, margin=1e-9) -> bool:
    """Same exact (closed cells, column walk) rule as vnrrt.planners.segment_free."""
    h, w = len(g), len(g[0])
    if x0 > x1:
        x0, y0, x1, y1 = x1, y1, x0, y0
    dx = x1 - x0
    slope = (y1 - y0) / dx if dx > 0 else 0.0
    c_lo, c_hi = math.floor(x0 - margin), math.floor(x1 + margin)
    if c_lo < 0 or c_hi >= w:
        return False
    for cx in range(c_lo, c_hi + 1):
        xa, xb = min(max(x0, cx), x1), max(min(x1, cx + 1), x0)
        ya, yb = (y0 + (xa - x0) * slope, y0 + (xb - x0) * slope) if dx > 0 else (y0, y1)
        r_lo, r_hi = math.floor(min(ya, yb) - margin), math.floor(max(ya, yb) + margin)
        if r_lo < 0 or r_hi >= h:
            return False
        for cy in range(r_lo, r_hi + 1):
            if g[cy][cx]:
                return False
    return True


def python_rrt_star(g, start, goal, bounds, seed, time_limit) -> dict:
    """Textbook RRT*: node lists, linear Nearest/Near, choose parent, rewire, propagate."""
    rng = np.random.default_rng(seed)
    grid = g.tolist()
    h, w = g.shape
    gamma = 2 * math.sqrt(1.5) * math.sqrt(np.count_nonzero(g == 0) / math.pi)
    xs, ys, cost, parent, children = [start[0]], [start[1]], [0.0], [-1], [[]]
    goal_parent, goal_cost = -1, math.inf
    times, t0 = {}, time.perf_counter()
    while time.perf_counter() - t0 < time_limit and len(times) < len(bounds):
        sx, sy = rng.random() * w, rng.random() * h
        near_i = min(range(len(xs)), key=lambda i: (xs[i] - sx) ** 2 + (ys[i] - sy) ** 2)
        d = math.hypot(sx - xs[near_i], sy - ys[near_i])
        if d == 0:
            continue
        t = min(1.0, ETA / d)
        x, y = xs[near_i] + t * (sx - xs[near_i]), ys[near_i] + t * (sy - ys[near_i])
        if not py_segment_free(grid, xs[near_i], ys[near_i], x, y):
            continue
        n = len(xs)
        r = min(gamma * math.sqrt(math.log(n + 1) / (n + 1)), ETA)
        near = [i for i in range(n) if (xs[i] - x) ** 2 + (ys[i] - y) ** 2 <= r * r]
        best, best_c = near_i, cost[near_i] + t * d
        for i in near:
            c = cost[i] + math.hypot(xs[i] - x, ys[i] - y)
            if c < best_c and py_segment_free(grid, xs[i], ys[i], x, y):
                best, best_c = i, c
        xs.append(x), ys.append(y), cost.append(best_c), parent.append(best), children.append([])
        children[best].append(n)
        for i in near:
            c = best_c + math.hypot(xs[i] - x, ys[i] - y)
            if c < cost[i] - 1e-9 and py_segment_free(grid, xs[i], ys[i], x, y):
                children[parent[i]].remove(i)
                parent[i] = n
                children[n].append(i)
                _propagate(i, c - cost[i], cost, children)
        if goal_parent >= 0:
            goal_cost = cost[goal_parent] + math.dist((xs[goal_parent], ys[goal_parent]), goal)
        dg = math.dist((x, y), goal)
        if dg <= ETA and best_c + dg < goal_cost and py_segment_free(grid, x, y, *goal):
            goal_parent, goal_cost = n, best_c + dg
        for key, b in bounds.items():
            if key not in times and goal_cost < math.inf and goal_cost <= b:
                times[key] = time.perf_counter() - t0
    return {"times": times, "iterations": len(xs)}


def _propagate(i, delta, cost, children):
    stack = [i]
    cost[i] += delta
    while stack:
        for c in children[stack.pop()]:
            cost[c] += delta
            stack.append(c)


# --- OMPL RRTstar ----------------------------------------------------------------------------


def ompl_rrt_star(g, start, goal, bounds, time_limit) -> dict:
    """OMPL RRTstar, RealVectorStateSpace(2), a Python point validity checker over ``g``
    with motions checked every 0.5 px; a termination callback records the bound times."""
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
    objective.setCostThreshold(ob.Cost(min(bounds.values())))
    pdef.setOptimizationObjective(objective)
    planner = og.RRTstar(si)
    planner.setRange(ETA)
    planner.setProblemDefinition(pdef)
    planner.setup()
    times, t0 = {}, time.perf_counter()

    def stop() -> bool:
        now, c = time.perf_counter() - t0, planner.bestCost().value()
        for key, b in bounds.items():
            if key not in times and c < math.inf and c <= b:
                times[key] = now
        return now >= time_limit or len(times) == len(bounds)

    planner.solve(ob.PlannerTerminationCondition(stop))
    stop()  # OMPL returns as soon as its cost threshold is met, before asking stop() again
    ok = pdef.hasExactSolution()
    path = np.array([[st[0], st[1]] for st in pdef.getSolutionPath().getStates()]) if ok else None
    clipped = path is not None and not path_free(g, path)
    return {"times": times, "iterations": planner.numIterations(), "clipped": clipped}


# --- ours and the report ---------------------------------------------------------------------


def ours(g, start, goal, bounds, seed, time_limit) -> dict:
    """This package's RRT*: stop at 1% of the any-angle length, timing 1% of A* on the way."""
    ref = bounds["any_angle"] / 1.01  # plan's target is (1 + eps) x ref with eps = 0.01
    r = plan(g, start, goal, "rrt_star", stop="optimal", reference_length=ref,
             milestones=(bounds["astar"],), seed=seed, eta=ETA, max_seconds=time_limit)  # fmt: skip
    times = {"first": r.time_to_first, "astar": r.milestones[0].time}
    times["any_angle"] = r.time_to_stop if r.success else math.nan
    clipped = len(r.path) > 0 and not path_free(g, r.path)
    return {"times": {k: v for k, v in times.items() if not math.isnan(v)},
            "iterations": r.iterations, "clipped": clipped}  # fmt: skip


def summarize(runs: dict[str, list[dict]], time_limit: float) -> dict:
    """Median seconds per planner and bound (``(value, censored)``)."""
    out = {}
    for name, rs in runs.items():
        for key in KEYS:
            vals = np.array([r["times"].get(key, math.inf) for r in rs])
            med = float(np.median(np.minimum(vals, time_limit)))
            censored = np.count_nonzero(np.isinf(vals)) * 2 >= len(vals)
            out[name, key] = (med, censored, int(np.isfinite(vals).sum()), len(vals))
    return out


def report(stats: dict, runs: dict, names: list[str]) -> None:
    print(f"\n{'median seconds':<28}" + "".join(f"{n:>18}" for n in names))
    labels = {
        "first": "first solution",
        "astar": "<= 1.01 x A*",
        "any_angle": "<= 1.01 x any-angle",
    }
    for key in KEYS:
        cells = []
        for n in names:
            med, cens, k, tot = stats[n, key]
            cells.append(f"{'>=' if cens else ''}{med:.4g} ({k}/{tot})")
        print(f"{labels[key]:<28}" + "".join(f"{c:>18}" for c in cells))
    print("\nspeed-up of ours (median other / median ours):")
    for other in names[1:]:
        for key in KEYS:
            (a, ca, *_), (b, cb, *_) = stats["ours", key], stats[other, key]
            mark = ">=" if cb and not ca else ("?" if ca else "")
            print(f"  vs {other:<8} {labels[key]:<22} {mark}{b / a:.1f}x")
    for n in names:
        clipped = sum(r.get("clipped", False) for r in runs[n])
        print(f"{n}: final paths clipping an obstacle (exact test): {clipped}/{len(runs[n])}")


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--maps", type=int, default=20)
    ap.add_argument("--trials", type=int, default=1, help="runs per map and planner")
    ap.add_argument("--time-limit", type=float, default=5.0, help="seconds per run")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--skip", nargs="*", default=[], choices=["python", "ompl"])
    args = ap.parse_args(argv)
    from ompl import util as ou

    ou.setLogLevel(ou.LogLevel.LOG_WARN)
    ou.RNG.setSeed(args.seed + 1)
    warmup()  # JIT compilation (or cache load) outside every timing
    names = ["ours"] + [n for n in ("python", "ompl") if n not in args.skip]
    runs = {n: [] for n in names}
    for m, (g, s, e) in enumerate(make_instances(args.maps, args.seed)):
        a, t = astar_length(g, s, e), any_angle_length(g, s, e)
        bounds = {"first": math.inf, "astar": 1.01 * a, "any_angle": 1.01 * t}
        for k in range(args.trials):
            seed = (args.seed, m, k)
            runs["ours"].append(ours(g, s, e, bounds, seed, args.time_limit))
            if "python" in runs:
                runs["python"].append(python_rrt_star(g, s, e, bounds, seed, args.time_limit))
            if "ompl" in runs:
                runs["ompl"].append(ompl_rrt_star(g, s, e, bounds, args.time_limit))
        line = " ".join(
            f"{n}={runs[n][-1]['times'].get('any_angle', math.inf):.3g}s" for n in names
        )
        print(f"map {m:2d}: A* {a:6.1f} any-angle {t:6.1f}  to 1% any-angle: {line}", flush=True)
    report(summarize(runs, args.time_limit), runs, names)


if __name__ == "__main__":
    main()
    sys.stdout.flush()
    sys.stderr.flush()
    os._exit(0)  # skip interpreter teardown: OMPL's nanobind bindings print leak warnings
