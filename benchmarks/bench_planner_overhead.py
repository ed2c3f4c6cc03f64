"""Benchmark: the per-call cost of our planner against native OMPL's solve, where the work is
least: maps whose straight start-goal segment is free (one segment test answers them) and a
few easy maps.

Per map, in one process, in warm loops (``--calls`` calls each, the median reported): our
whole ``plan()`` call (input checks, setup, seeding, the run, the result), a reusable
:class:`vnrrt.planners.Planner` set up once (its setup timed apart) and its ``solve()`` call,
our run's own time; native OMPL's (:mod:`ompl_native`) BITstar, ABITstar, AITstar and
InformedRRTstar at their defaults, each its ``solve()`` time and its setup (space, problem,
planner, ``setup()``), and the best solve of them. All stop at 1.01 x the exact optimum.

    python benchmarks/bench_planner_overhead.py [--calls 200]
"""

from __future__ import annotations

import argparse
import math
import sys
import time

import numpy as np

import ompl_native
from planner_maps import dev_instances, held_out_instances
from vnrrt.planners import FASTEST, Planner, any_angle_path, plan, segment_free, warmup

NATIVE = ("BITstar", "ABITstar", "AITstar", "InformedRRTstar")
EASY = ("open", "random1", "random11")


def ours(g, s, e, exact, calls: int) -> dict[str, float]:
    """Median seconds: plan() call, Planner() setup, Planner.solve() call, the run itself."""
    out: dict[str, list[float]] = {"plan": [], "setup": [], "solve": [], "run": []}
    for k in range(calls):
        t0 = time.perf_counter()
        plan(g, s, e, stop="optimal", reference_length=exact, seed=k, config=FASTEST)
        out["plan"].append(time.perf_counter() - t0)
    for _ in range(calls):
        t0 = time.perf_counter()
        planner = Planner(g, config=FASTEST)
        out["setup"].append(time.perf_counter() - t0)
    for k in range(calls):
        t0 = time.perf_counter()
        r = planner.solve(s, e, stop="optimal", reference_length=exact, seed=k)
        out["solve"].append(time.perf_counter() - t0)
        out["run"].append(r.time_to_stop)
    return {key: float(np.median(v)) for key, v in out.items()}


def native(h, g, s, e, bound: float, calls: int) -> dict[str, tuple[float, float]]:
    """Per planner: median seconds of its solve() (to ``bound``) and of its setup."""
    h.set_map(g)
    out = {}
    for name in NATIVE:
        runs = [h.solve(name, s, e, bound, 2.0) for _ in range(calls)]
        stop = [r.stop if not math.isnan(r.stop) else 2.0 for r in runs]
        out[name] = (float(np.median(stop)), float(np.median([r.setup for r in runs])))
    return out


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--calls", type=int, default=200, help="calls per map and planner")
    args = ap.parse_args(argv)
    binary = ompl_native.build_or_explain()
    if binary is None:
        return 2
    warmup()
    maps = [m for m in dev_instances() + held_out_instances()
            if segment_free(m[1], *m[2], *m[3]) or m[0] in EASY]  # fmt: skip
    print(f"median us over {args.calls} warm calls; 'free': the straight segment is free")
    print(
        f"{'map':<12}{'run':>8}{'solve()':>9}{'plan()':>9}{'Planner()':>10}"
        f"{'best native':>18}{'its setup':>10}{'plan()/native':>15}{'solve()/native':>15}"
    )
    ratios = {"plan": [], "solve": []}
    with ompl_native.Harness(binary, 1) as h:
        for name, g, s, e in maps:
            exact = any_angle_path(g, s, e)[1]
            us = ours(g, s, e, exact, args.calls)
            nat = native(h, g, s, e, 1.01 * exact, args.calls)
            best = min(nat, key=lambda n: nat[n][0])
            stop, setup = nat[best]
            for key in ratios:
                ratios[key].append(us[key] / stop)
            tag = " free" if segment_free(g, *s, *e) else ""
            print(f"{name + tag:<15}{1e6 * us['run']:8.1f}{1e6 * us['solve']:9.1f}"
                  f"{1e6 * us['plan']:9.1f}{1e6 * us['setup']:10.1f}"
                  f"{f'{best} {1e6 * stop:.1f}':>22}{1e6 * setup:10.1f}"
                  f"{ratios['plan'][-1]:15.2f}{ratios['solve'][-1]:15.2f}")  # fmt: skip
    for key, label in (("plan", "plan() call"), ("solve", "Planner.solve() call")):
        r = ratios[key]
        print(
            f"{label} / best native solve(): median {np.median(r):.2f}, worst {max(r):.2f}, "
            f"below 1 on {sum(v < 1 for v in r)} of {len(r)} maps"
        )
    return 0


if __name__ == "__main__":
    sys.exit(main())
