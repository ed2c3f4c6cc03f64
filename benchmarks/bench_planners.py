"""Benchmark: our planners against native OMPL (C++) and OMPL's Python bindings, and the floor.

In one process, on the same maps (:mod:`planner_maps`: a development set and a held-out set,
reported apart) and start/goal pairs, alternating per trial: our best configuration
(``ours-best``, :data:`vnrrt.planners.FASTEST`: informed, straight segment first, goal joined
by any node that sees it, Steer step 20 px, path refinement, pulled parents, the gap sampler)
and our
paper-setting RRT* (step 10 px); native OMPL 1.5
(a C++ harness built here against the system's ``libompl-dev``, :mod:`ompl_native`): RRTstar,
InformedRRTstar, BITstar, ABITstar and AITstar at their defaults and the two RRT* planners at
our step ("-m", matched); OMPL's Python bindings (:mod:`ompl_python`, a Python validity
checker): RRTstar, InformedRRTstar and BITstar at defaults and the RRT* two matched. OMPL
checks motions every 0.5 px and stops itself at its cost threshold, 1.01 x the exact optimum.

Every run records, in seconds from the start of the planner's own timed region (our run;
OMPL's ``solve()``, its setup apart), the time to its first solution and to a cost within 1%
of the exact continuous optimum (:func:`vnrrt.planners.any_angle_path`); a run stops there or
at ``--time-limit`` (a miss counts as the limit: medians marked ">=" are lower bounds).
``ours-call`` is the whole ``plan()`` call (input checks, setup, seeding and result
included); our calls run with the garbage collector off and their garbage is collected
after them (``--collect-before``: right before each call, which leaves the call's caches
cold). Per map: medians over trials and the ratio of the best native OMPL
planner's median to ours; overall: each planner's median over maps, the ratio of the best
OMPL planner's (native, then Python) to ours, and the median and worst per-map ratio (for
the whole call too). The floor is the exact visibility-graph solve itself, timed per map.
Every path of ours is checked with the exact segment test and against the stop rule (exit 1
if one fails); OMPL's paths that clip an obstacle corner under that test are counted. Exit 2
when the harness cannot be built. OMPL's Python bindings run with the garbage collector on.

Every timed run, ours and OMPL's alike, follows an untimed run of the same planner and query
with a 1 ms budget (``--warm SECONDS``, default 0.001), while trials still alternate between the
planners. (OMPL's own benchmark tool, ``ompl::tools::Benchmark::benchmark``, also runs one
planner's runs back to back, planners in the outer loop, though with ``clear()``, path checks
and simplification between runs rather than a warm-up run.) ``--warm 0`` is a second reading (it
changes the verdict on the maps whose straight segment is free): there our first call of a
trial follows the Python bindings' runs of the one before, with cold caches, while each
native planner follows the others' runs on the same map and its own setup in its harness,
warmer. ``--flush MB`` (a third reading, with ``--warm 0``) writes and reads that
many MB of a buffer in the planner's own process (ours and the Python bindings' here, native
OMPL's in its harness) after the warm-up run, if any, and right before every timed run, so
that every planner starts with caches disturbed alike (not emptied: with a last-level cache
larger than the flush, cold times keep growing with its size). Every reading is written to
``benchmarks/results/bench_planners.txt`` (its header names the reading, machine and code).

    python benchmarks/bench_planners.py [--trials 5] [--time-limit 2] [--sets dev,held_out]
        [--warm 0.001] [--flush 0]
"""

from __future__ import annotations

import argparse
import gc
import math
import os
import sys
import time

import numpy as np

import ompl_native
import ompl_python
from planner_maps import dev_instances, held_out_instances
from vnrrt.planners import FASTEST, PlannerConfig, any_angle_path, path_free, plan, warmup

ETA, BEST_ETA = 10.0, FASTEST.eta
OURS = {"ours-best": FASTEST, "ours-rrt*": PlannerConfig(eta=ETA)}
NATIVE = [*ompl_native.PLANNERS, "RRTstar-m", "InformedRRTstar-m"]
PYTHON = [*ompl_python.PLANNERS, "RRTstar-m", "InformedRRTstar-m"]


COLLECT_BEFORE = False  # --collect-before: garbage collected right before each of our calls
WARM = 0.001  # --warm: seconds of an untimed run of each planner before each of its timed ones
FLUSH = 0  # --flush: bytes written and read in a planner's process before each of its timed runs
_BUFFER = np.zeros(0, np.uint8)  # this process's flush buffer


def flush_here(nbytes: int) -> int:
    """Write and read ``nbytes`` bytes (every 64-byte line) of a buffer kept for the purpose,
    evicting the CPU caches of this process's next run; returns the sum read."""
    global _BUFFER
    if _BUFFER.size != nbytes:
        _BUFFER = np.zeros(nbytes, np.uint8)
    _BUFFER[::64] += 1
    return int(_BUFFER[::64].sum())


def run_ours(g, s, e, exact, seed, config) -> dict:
    """Our planner to 1% of ``exact``; times of the run and of the whole call, made with
    Python's garbage collector off (as :mod:`timeit` does; garbage is collected after our
    calls of a trial, before OMPL's: :func:`bench_map`)."""
    if COLLECT_BEFORE:
        gc.collect()
    gc.disable()
    try:
        t0 = time.perf_counter()
        r = plan(g, s, e, stop="optimal", reference_length=exact, seed=seed, config=config)
        call = time.perf_counter() - t0
    finally:
        gc.enable()
    ok = path_free(g, r.path) and (not r.success or r.cost <= 1.01 * exact + 1e-9)
    stop = r.time_to_stop if r.success else math.nan
    return {"first": r.time_to_first, "stop": stop, "call": call if r.success else math.nan,
            "clipped": not ok}  # fmt: skip


def run_native(h, g, s, e, bound, limit, name) -> dict:
    algo, step = name.removesuffix("-m"), BEST_ETA if name.endswith("-m") else 0.0
    r = h.solve(algo, s, e, bound, limit, step)
    clipped = len(r.path) > 0 and not path_free(g, r.path)
    return {"first": r.first, "stop": r.stop, "setup": r.setup, "clipped": clipped}


def run_python(g, s, e, bound, limit, name) -> dict:
    algo, step = name.removesuffix("-m"), BEST_ETA if name.endswith("-m") else 0.0
    r = ompl_python.solve(g, s, e, bound, limit, algo, step)
    clipped = r["path"] is not None and not path_free(g, r["path"])
    return {"first": r["first"], "stop": r["stop"], "clipped": clipped}


def floor_seconds(g, s, e, repeats: int = 5) -> float:
    """Median seconds of the exact solve (the visibility-graph A*, a whole call)."""
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        any_angle_path(g, s, e)
        times.append(time.perf_counter() - t0)
    return float(np.median(times))


def bench_map(native, g, s, e, trials, limit, seed, python) -> dict:
    """Every planner's runs on one instance, alternating per trial."""
    exact = any_angle_path(g, s, e)[1]
    bound = 1.01 * exact
    native.set_map(g)
    runs: dict[str, list[dict]] = {}
    for k in range(trials):
        for label, config in OURS.items():
            config = config.replace(max_seconds=limit)  # validated here, not in the timed call
            if WARM:
                run_ours(g, s, e, exact, (*seed, k, 1), config.replace(max_seconds=WARM))
            if FLUSH:
                flush_here(FLUSH)
            runs.setdefault(label, []).append(run_ours(g, s, e, exact, (*seed, k), config))
        gc.collect()  # our calls' garbage, outside every timed call
        for name in NATIVE:
            if WARM:
                run_native(native, g, s, e, bound, WARM, name)
            if FLUSH:
                native.flush(FLUSH)
            runs.setdefault(f"n-{name}", []).append(run_native(native, g, s, e, bound, limit, name))
        for name in PYTHON if python else ():
            if WARM:
                run_python(g, s, e, bound, WARM, name)
            if FLUSH:
                flush_here(FLUSH)
            runs.setdefault(f"p-{name}", []).append(run_python(g, s, e, bound, limit, name))
    return {"exact": exact, "floor": floor_seconds(g, s, e), "runs": runs}


def median_time(runs: list[dict], key: str, limit: float) -> tuple[float, bool]:
    """Median seconds to ``key`` over trials (a miss counts as ``limit``), and whether it is
    a lower bound (half or more missed)."""
    vals = np.array([r[key] for r in runs])
    missed = np.isnan(vals)
    return float(np.median(np.where(missed, limit, vals))), 2 * missed.sum() >= len(vals)


def _cell(value: float, lower: bool, wide: int) -> str:
    return f"{('>=' if lower else '') + f'{1e3 * value:.3g}':>{wide}}"


def medians(per_map: dict, names: list[str], key: str, limit: float) -> dict:
    """``{map: {planner: (median s, lower bound)}}``; ``ours-call`` is ours-best's call."""

    def one(runs: dict, n: str) -> tuple[float, bool]:
        if n == "ours-call":
            return median_time(runs["ours-best"], "call", limit)
        return median_time(runs[n], key, limit)

    return {m: {n: one(v["runs"], n) for n in names} for m, v in per_map.items()}


def summary(meds: dict, ours: str, group: list[str], short: dict) -> str:
    """``ours`` against the best of ``group``: the ratio of the medians over maps (the best
    planner of the group by its median over maps), the per-map ratio's median and worst."""
    overall = {n: float(np.median([med[n][0] for med in meds.values()])) for n in [ours, *group]}
    best = min(group, key=overall.get)
    ratios = sorted((min(med[n][0] for n in group) / max(med[ours][0], 1e-9), m)
                    for m, med in meds.items())  # fmt: skip
    vals = [r for r, _ in ratios]
    return (f"{ours} vs the best of {short[group[0]][:2]}*: median over maps "
            f"{overall[best] / overall[ours]:.1f}x ({short[best]} {1e3 * overall[best]:.3g} ms "
            f"vs {1e3 * overall[ours]:.3g} ms); per map: median {np.median(vals):.1f}x, worst "
            f"{ratios[0][0]:.2f}x ({ratios[0][1]}), slower on {sum(v < 1 for v in vals)} of "
            f"{len(vals)} maps")  # fmt: skip


def table(per_map: dict, key: str, limit: float) -> None:
    """Per-map medians (ms) of every planner to ``key``, the best native planner and the
    ratio to ours; the median over maps and the summary lines."""
    names = [n for n in next(iter(per_map.values()))["runs"] if n != "ours-best"]
    names = ["ours-best", *(["ours-call"] if key == "stop" else []), *names]
    natives = [n for n in names if n.startswith("n-")]
    pythons = [n for n in names if n.startswith("p-")]
    short = {n: n.replace("Informed", "I").replace("star", "*") for n in names}
    wide = max(9, *(len(v) + 1 for v in short.values()))
    meds = medians(per_map, names, key, limit)
    print(f"{'map':<15}" + "".join(f"{short[n]:>{wide}}" for n in names)
          + f"{'best native':>13}{'ratio':>8}")  # fmt: skip
    for name, med in meds.items():
        best = min(natives, key=lambda n: med[n][0])
        ratio = (
            ">=" if med[best][1] else ""
        ) + f"{med[best][0] / max(med['ours-best'][0], 1e-9):.1f}"
        cells = "".join(_cell(*med[n], wide) for n in names)
        print(f"{name:<15}{cells}{short[best]:>13}{ratio:>8}")
    overall = {n: np.median([med[n][0] for med in meds.values()]) for n in names}
    print(f"{'median of maps':<15}" + "".join(f"{1e3 * overall[n]:>{wide}.3g}" for n in names))
    print(summary(meds, "ours-best", natives, short))
    if key == "stop":
        print(summary(meds, "ours-call", natives, short))
    if pythons:
        print(summary(meds, "ours-best", pythons, short))


def report(title: str, per_map: dict, limit: float) -> bool:
    """Print a set's tables, floor and path checks; False when one of our paths failed."""
    print(f"\n===== {title}: {len(per_map)} maps =====")
    for key, label in (("first", "first solution"), ("stop", "<= 1.01 x exact optimum")):
        print(f"\nmedian ms to the {label}, per map (ratio = best native OMPL / ours-best)")
        table(per_map, key, limit)
    print("\nthe floor: the exact solve (visibility-graph A*) against ours-best to 1%")
    rows = []
    for name, m in per_map.items():
        ours = median_time(m["runs"]["ours-best"], "call", limit)[0]
        rows.append(ours / m["floor"])
        print(f"{name:<15}exact {1e3 * m['floor']:8.3f} ms  ours-best call {1e3 * ours:8.3g} ms"
              f"  ours / exact {rows[-1]:7.2f}")  # fmt: skip
    print(
        f"ours-best call / exact solve: median over maps {np.median(rows):.2f}, "
        f"best {min(rows):.2f}, worst {max(rows):.2f}"
    )
    good = True
    for n in next(iter(per_map.values()))["runs"]:
        runs = [r for m in per_map.values() for r in m["runs"][n]]
        bad = sum(r["clipped"] for r in runs)
        good &= bad == 0 or not n.startswith("ours")
        what = "paths failing the exact test or the stop rule" if n.startswith("ours") else (
            "final paths clipping an obstacle (exact test)")  # fmt: skip
        print(f"{n}: {what}: {bad}/{len(runs)}")
    return good


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--trials", type=int, default=5, help="runs per map and planner")
    ap.add_argument("--time-limit", type=float, default=2.0, help="seconds per run")
    ap.add_argument("--sets", default="dev,held_out", help="dev, held_out or both")
    ap.add_argument("--maps", help="only these maps (comma-separated names)")
    ap.add_argument("--no-python", action="store_true", help="skip OMPL's Python bindings")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--collect-before", action="store_true",
                    help="collect garbage right before each of our calls (it leaves the "
                         "next call's caches cold)")  # fmt: skip
    ap.add_argument("--warm", type=float, default=0.001, metavar="SECONDS",
                    help="before each timed run, an untimed run of the same planner and query "
                         "with this budget (every planner, ours and OMPL's, starts warm, as each "
                         "run in OMPL's benchmark tool follows the same planner's; default "
                         "0.001; 0: none)")  # fmt: skip
    flush = "before each timed run (after --warm's), write and read this many MB in the "
    flush += "planner's process: every planner starts with caches disturbed alike"
    ap.add_argument("--flush", type=float, default=0.0, metavar="MB", help=flush)
    args = ap.parse_args(argv)
    if args.warm < 0 or args.flush < 0:
        ap.error("--warm and --flush must be >= 0")
    global COLLECT_BEFORE, WARM, FLUSH
    COLLECT_BEFORE, WARM, FLUSH = args.collect_before, args.warm, int(args.flush * 2**20)
    binary = ompl_native.build_or_explain()
    if binary is None:
        return 2
    if not args.no_python:
        ompl_python.quiet(args.seed + 1)
    warmup()  # JIT compilation (or cache load) outside every timing
    sets = {"dev": dev_instances, "held_out": held_out_instances}
    good = True
    with ompl_native.Harness(binary, args.seed + 1) as native:
        for set_name in args.sets.split(","):
            per_map = {}
            for m, (name, g, s, e) in enumerate(sets[set_name](seed=args.seed)):
                m += 1000 * list(sets).index(set_name)
                if args.maps and name not in args.maps.split(","):
                    continue
                per_map[name] = bench_map(native, g, s, e, args.trials, args.time_limit,
                                          (args.seed, m), not args.no_python)  # fmt: skip
                print(f"{set_name} {name}: exact optimum {per_map[name]['exact']:.1f} px",
                      flush=True)  # fmt: skip
            good &= report(set_name, per_map, args.time_limit)
    return 0 if good else 1


if __name__ == "__main__":
    code = main()
    sys.stdout.flush()
    sys.stderr.flush()
    os._exit(code)  # skip interpreter teardown: OMPL's nanobind bindings print leak warnings
