"""Benchmark: the per-call cost of our planner against native OMPL's solve, where the work is
least: maps whose straight start-goal segment is free (one segment test answers them) and a
few easy maps.

Per map, in one process, ``--calls`` calls of each figure (the median reported), made in
blocks of ``--block`` warm calls that alternate between ours and OMPL's: our whole ``plan()``
call (input checks, setup, seeding, the run, the result), a :class:`vnrrt.planners.Planner`
set up (``Planner()``) and its ``solve()`` call, our run's own time, and native OMPL's
(:mod:`ompl_native`) BITstar, ABITstar, AITstar and InformedRRTstar at their defaults (each
its ``solve()`` time and its setup: space, problem, planner, ``setup()``); the best native
planner is the one with the lowest median solve. Each side runs warm within a block, as
OMPL's own process always is, and the blocks alternate so that a slow phase of a shared
machine falls on both (on this machine the same call's time varies 2x from one minute to the
next: separate loops compared phases, not planners). ``--block 1`` interleaves single calls
instead: each of ours then follows OMPL's calls and their pipe traffic, with colder caches.
Python's garbage collector is off during our timed calls (as :mod:`timeit` does); OMPL's C++
has none. All stop at 1.01 x the exact optimum.

    python benchmarks/bench_planner_overhead.py [--calls 200] [--block 10]
"""

from __future__ import annotations

import argparse
import functools
import gc
import math
import sys
import time

import numpy as np

import ompl_native
from planner_maps import dev_instances, held_out_instances
from vnrrt.planners import FASTEST, Planner, any_angle_path, plan, segment_free, warmup
from vnrrt.planners.native import described

NATIVE = ("BITstar", "ABITstar", "AITstar", "InformedRRTstar")
EASY = ("open", "random1", "random11")


def timed(fn):
    """``fn()`` and the seconds it took, the garbage collector off meanwhile."""
    gc.disable()
    try:
        t0 = time.perf_counter()
        out = fn()
        return out, time.perf_counter() - t0
    finally:
        gc.enable()


def rounds(h, g, s, e, exact: float, calls: int, block: int) -> tuple[dict, dict]:
    """Median seconds of ours (``plan``, ``setup``, ``solve``, ``run``) and, per native
    planner, of its ``solve()`` (to 1.01 x ``exact``) and its setup, over alternating blocks
    of ``block`` calls each."""
    h.set_map(g)
    us: dict[str, list[float]] = {"plan": [], "setup": [], "solve": [], "run": []}
    nat: dict[str, list[tuple[float, float]]] = {name: [] for name in NATIVE}
    for b in range(0, calls, block):
        seeds = range(b, min(b + block, calls))
        for k in seeds:
            _, t = timed(lambda k=k: plan(g, s, e, stop="optimal", reference_length=exact,
                                          seed=k, config=FASTEST))  # fmt: skip
            us["plan"].append(t)
        for _ in seeds:
            planner, t = timed(lambda: Planner(g, config=FASTEST))
            us["setup"].append(t)
        for k in seeds:
            r, t = timed(functools.partial(planner.solve, s, e, stop="optimal",
                                           reference_length=exact, seed=k))  # fmt: skip
            us["solve"].append(t)
            us["run"].append(r.time_to_stop)
        for name in NATIVE:
            for _ in seeds:
                n = h.solve(name, s, e, 1.01 * exact, 2.0)
                nat[name].append((n.stop if not math.isnan(n.stop) else 2.0, n.setup))
    ours = {key: float(np.median(v)) for key, v in us.items()}
    native = {name: tuple(float(x) for x in np.median(np.array(v), axis=0))
              for name, v in nat.items()}  # fmt: skip
    return ours, native


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--calls", type=int, default=200, help="calls per map and planner")
    ap.add_argument("--block", type=int, default=10, help="warm calls per alternating block")
    args = ap.parse_args(argv)
    binary = ompl_native.build_or_explain()
    if binary is None:
        return 2
    warmup()
    print(described())
    maps = [m for m in dev_instances() + held_out_instances()
            if segment_free(m[1], *m[2], *m[3]) or m[0] in EASY]  # fmt: skip
    print(f"median us over {args.calls} calls in alternating blocks of {args.block}; "
          "'free': the straight segment is free")  # fmt: skip
    print(
        f"{'map':<12}{'run':>8}{'solve()':>9}{'plan()':>9}{'Planner()':>10}"
        f"{'best native':>18}{'its setup':>10}{'plan()/native':>15}{'solve()/native':>15}"
    )
    ratios = {"plan": [], "solve": []}
    with ompl_native.Harness(binary, 1) as h:
        for name, g, s, e in maps:
            exact = any_angle_path(g, s, e)[1]
            us, nat = rounds(h, g, s, e, exact, args.calls, args.block)
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
