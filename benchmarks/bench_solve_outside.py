"""Benchmark: the microseconds of a call outside its planner run, on maps that need a tree.

Per map (``open``, ``random1``, ``random11`` of the development set, our fastest settings, to
1.01 x the exact optimum), ``--calls`` calls alternating a reused :class:`Planner`'s
``solve()`` and a one-shot ``plan()``, the garbage collector off during each; prints the
medians of ``solve()``, of ``solve()`` minus its run (``time_to_stop``: input checks, setup of
the compiled call, the result) and of ``plan()``. To compare two versions of the code, run it
alternately with each on ``PYTHONPATH`` (one process's figures vary by 20-40% on a shared
machine; compare medians over several processes).

    python benchmarks/bench_solve_outside.py [--calls 600] [--tag after]
"""

from __future__ import annotations

import argparse
import functools
import sys

import numpy as np

from bench_planner_overhead import timed
from planner_maps import dev_instances
from vnrrt.planners import FASTEST, Planner, any_angle_path, plan, warmup

MAPS = ("open", "random1", "random11")


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--calls", type=int, default=600, help="calls per map of each kind")
    ap.add_argument("--tag", default="", help="a label printed first on the line")
    args = ap.parse_args(argv)
    warmup()
    maps = {m[0]: m for m in dev_instances()}
    parts = []
    for name in MAPS:
        _, g, s, e = maps[name]
        exact = any_angle_path(g, s, e)[1]
        planner = Planner(g, config=FASTEST)
        solve, outside, once = [], [], []
        ask = {"stop": "optimal", "reference_length": exact}
        for k in range(args.calls):
            r, t = timed(functools.partial(planner.solve, s, e, seed=k, **ask))
            solve.append(t)
            outside.append(t - r.time_to_stop)
            _, t = timed(functools.partial(plan, g, s, e, seed=k, config=FASTEST, **ask))
            once.append(t)
        us = [1e6 * float(np.median(v)) for v in (solve, outside, once)]
        parts.append(f"{name}: solve {us[0]:.1f} outside-run {us[1]:.1f} plan {us[2]:.1f}")
    print(" ".join(filter(None, [args.tag, " | ".join(parts)])))
    return 0


if __name__ == "__main__":
    sys.exit(main())
