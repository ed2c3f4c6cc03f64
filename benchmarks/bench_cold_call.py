"""Benchmark: what a call costs with cold caches, against the same call warm, where our planner
does least: the run of a free straight segment, one compiled call (``core.query_test``).

On each of the development maps whose straight segment is free, the median over ``--calls``
calls of: a Python function of the same six arguments (the baseline), a trivial compiled
(numba) function of them, our run's compiled call through numba's dispatch, the C answer
(:mod:`vnrrt.planners.native`: the same test called through its C address, and the result),
the whole ``plan()`` call that uses it (its arguments recognised in C) and the ``solve()``
call of a :class:`vnrrt.planners.Planner` set up once; each timed cold (right after ``--flush``
MB of a buffer are written and read, as ``bench_planners.py --flush``) and warm (back to back).
The ratios are to the Python call measured in the same run. It shows where a cold run's time
goes: the compiled call's dispatch (argument typing, unboxing) against the segment test.

    python benchmarks/bench_cold_call.py [--calls 60] [--flush 64]
"""

from __future__ import annotations

import argparse
import functools
import math
import time

import numpy as np
from numba import njit

from bench_planners import flush_here
from planner_maps import dev_instances
from vnrrt.planners import FASTEST, Planner, core, plan, segment_free, warmup
from vnrrt.planners.native import answerer, described


@njit(cache=True)
def trivial(occ, sx, sy, gx, gy, straight):
    """A compiled function of the run's arguments that does nothing (its dispatch alone)."""
    return sx


def python(occ, sx, sy, gx, gy, straight):
    """The same in Python: the baseline."""
    return sx


def median_us(fn, args: tuple, calls: int, flush: int) -> float:
    """Median microseconds of ``fn(*args)`` over ``calls`` calls, each after a flush of
    ``flush`` bytes (:func:`bench_planners.flush_here`) when nonzero, else back to back."""
    times = []
    for _ in range(calls):
        if flush:
            flush_here(flush)
        t0 = time.perf_counter()
        fn(*args)
        times.append(time.perf_counter() - t0)
    return 1e6 * float(np.median(times))


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--calls", type=int, default=60, help="calls per figure and map")
    ap.add_argument("--flush", type=float, default=64.0, metavar="MB", help="flush size")
    args = ap.parse_args(argv)
    warmup()
    nbytes = int(args.flush * 2**20)
    answer = answerer()
    print(described())  # the 'C answer' column is the Python one where C is not built
    print(f"median us over {args.calls} calls; cold: after a {args.flush:g} MB flush")
    labels = ("python call", "compiled no-op", "our run", "C answer", "plan() call", "solve() call")
    print(f"{'map':<10}" + "".join(f"{f + ' cold':>20}{'warm':>7}" for f in labels))
    ratios = {f: [] for f in labels}
    for name, g, s, e in dev_instances():
        occ = np.ascontiguousarray(g, np.uint8)
        xy = (*map(float, s), *map(float, e))
        if not segment_free(occ, *xy):
            continue
        d = math.hypot(xy[2] - xy[0], xy[3] - xy[1])
        query = {"stop": "optimal", "reference_length": d, "seed": 0}
        ask = {**query, "config": FASTEST}
        solve = Planner(occ, config=FASTEST).solve  # set up once, as OMPL's setup()
        figures = {
            "python call": (python, (occ, *xy, True)),
            "compiled no-op": (trivial, (occ, *xy, True)),
            "our run": (core.query_test, (occ, *xy, True)),  # through numba's dispatch
            "C answer": (answer, (occ, *xy, 1.01 * d, "rrt_star", d, 0.0, False)),
            "plan() call": (functools.partial(plan, occ, xy[:2], xy[2:], **ask), ()),
            "solve() call": (functools.partial(solve, xy[:2], xy[2:], **query), ()),
        }
        row = f"{name:<10}"
        base = None
        for label, (fn, args_) in figures.items():
            fn(*args_)  # compiled (or loaded) before timing
            cold = median_us(fn, args_, args.calls, nbytes)
            warm = median_us(fn, args_, 20 * args.calls, 0)
            base = base or cold
            ratios[label].append(cold / base)
            row += f"{cold:>20.2f}{warm:>7.2f}"
        print(row)
    for label, vals in ratios.items():
        print(f"{label}: cold / the Python call's cold, median over maps {np.median(vals):.2f}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
