"""Benchmark: a ``plan()`` call's time outside its run in ``bench_planners.py``'s sequence.

Per map (default: the five short tree runs ``open``, ``random1``, ``random11``, ``random_h1``,
``random_h6``), ``--trials`` times what :func:`bench_planners.bench_map` does in a trial:
our best configuration's untimed 1 ms run and its timed run (a new config object each trial,
as there), our paper-setting RRT*'s two runs, Python's garbage collected, then native OMPL's
RRTstar, InformedRRTstar, BITstar and ABITstar (each an untimed 1 ms run and a timed run, in
the harness's process). Prints per map the medians of our whole ``plan()`` call, of its run
(``time_to_stop``) and of their difference per trial: the time outside the run with the caches
as that benchmark leaves them (warmer than a flush, colder than a loop of calls:
``bench_planner_overhead.py``, ``bench_solve_outside.py``). To compare two versions of the
code, run it alternately with each on ``PYTHONPATH``, several processes each.

    python benchmarks/bench_call_in_sequence.py [--maps open,random1] [--trials 25] [--tag after]
"""

from __future__ import annotations

import argparse
import gc
import sys

import numpy as np

import ompl_native
from bench_planners import run_ours
from planner_maps import dev_instances, held_out_instances
from vnrrt.planners import FASTEST, PlannerConfig, any_angle_path, warmup

MAPS = "open,random1,random11,random_h1,random_h6"
NATIVE = ("RRTstar", "InformedRRTstar", "BITstar", "ABITstar")
WARM = 0.001  # seconds of each untimed run, as bench_planners' --warm


def trial(native, g, s, e, exact: float, k: int, limit: float) -> tuple[float, float]:
    """bench_planners' trial ``k`` on one map (ours, then native OMPL's; our calls timed by
    its :func:`bench_planners.run_ours`); our timed call's (whole call, run) in seconds."""
    best = FASTEST.replace(max_seconds=limit)
    run_ours(g, s, e, exact, (0, k, 1), best.replace(max_seconds=WARM))
    timed = run_ours(g, s, e, exact, (0, k), best)
    rrt = PlannerConfig(eta=10.0, max_seconds=limit)
    run_ours(g, s, e, exact, (0, k, 1), rrt.replace(max_seconds=WARM))
    run_ours(g, s, e, exact, (0, k), rrt)
    gc.collect()
    for name in NATIVE:
        native.solve(name, s, e, 1.01 * exact, WARM, 0.0)
        native.solve(name, s, e, 1.01 * exact, limit, 0.0)
    return timed["call"], timed["stop"]


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--maps", default=MAPS, help="comma-separated map names")
    ap.add_argument("--trials", type=int, default=25, help="trials per map")
    ap.add_argument("--time-limit", type=float, default=2.0, help="seconds per run")
    ap.add_argument("--tag", default="", help="a label printed first on the line")
    args = ap.parse_args(argv)
    binary = ompl_native.build_or_explain()
    if binary is None:
        return 2
    warmup()
    maps = {m[0]: m for m in (*dev_instances(), *held_out_instances())}
    parts = []
    with ompl_native.Harness(binary, 1) as native:
        for name in args.maps.split(","):
            _, g, s, e = maps[name]
            exact = any_angle_path(g, s, e)[1]
            native.set_map(g)
            calls, runs = np.array(
                [trial(native, g, s, e, exact, k, args.time_limit) for k in range(args.trials)]
            ).T
            us = [1e6 * float(np.median(v)) for v in (calls, runs, calls - runs)]
            parts.append(f"{name}: call {us[0]:.0f} run {us[1]:.0f} outside-run {us[2]:.0f}")
    print(" ".join(filter(None, [args.tag, " | ".join(parts)])))
    return 0


if __name__ == "__main__":
    sys.exit(main())
