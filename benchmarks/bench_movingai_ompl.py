"""Benchmark: our best configuration against native OMPL's best on the shipped MovingAI maps,
at an equal time budget per query.

The queries of ``bench_movingai.py`` (per map the ``--longest`` with the longest published
optimal lengths, from their cells' centres), ``--seeds`` seeds each. Ours: the default of
``plan()`` (:data:`vnrrt.planners.USER`, our fastest settings; its time budget capped at
``--limit``), RRT* stopping at 1.01 x the exact any-angle optimum
(:func:`vnrrt.search.any_angle_length`). Native OMPL 1.5 (``ompl_native``: C++ grid checker,
motions checked every 0.5 px, stopping at the same cost or at ``--limit`` s), at OMPL's
default settings and, matched (``-m``), with our Steer step (the default's ``eta``) as the
range of the planners that have one: RRT-Connect (and RRT-Connect-m) for first solutions,
BIT*, ABIT*, Informed RRT* and Informed RRT*-m to the bound (their first solutions counted
too). Per run, seconds from the start of the planner's own
solve to its first solution and to the bound, as each measures them (ours:
``time_to_first``/``time_to_stop``; OMPL: timed in C++ from the start of ``solve()``).
Runs alternate per query and seed, ours first. A final path that crosses an obstacle cell
(OMPL checks motions every 0.5 px, so its paths may cut a corner of a cell) is ``clipped``:
counted as its planner reported it in the first two tables, as unsolved in the last (to the
bound, where the final path is the one that reached it), and counted per planner and map.

Reported per map, for the first solution and for the bound: runs solved within the budget
by ours and by each OMPL planner, the medians over all runs (an unsolved run counts at the
budget, the median then marked ``>`` when it is one: a lower bound), OMPL's best planner
(least median; of equal ones, the one that solved most), the ratio of medians (best OMPL /
ours; ``>``: a lower bound) and the paired median speed-up over the runs that OMPL's best
solved (its time / ours on the same query and seed; ``-`` where it solved none), and the
clipped runs (ours first, then OMPL's in the table's order).

    python benchmarks/bench_movingai_ompl.py [--limit 5] [--longest 5] [--seeds 3]
        [--maps ...] [--out benchmarks/results/bench_movingai_ompl.txt]
"""

from __future__ import annotations

import argparse
import math
import os
import statistics
import sys
from pathlib import Path

import ompl_native
from bench_movingai import MAPS, machine, queries
from vnrrt.planners import USER, path_free, plan, warmup
from vnrrt.search import any_angle_length

ROOT = Path(__file__).resolve().parents[1]
MATCHED = "-m"  # a planner name's suffix: OMPL's range set to our Steer step (USER.eta)
FIRST = (ompl_native.RRT_CONNECT, ompl_native.RRT_CONNECT + MATCHED, "BITstar", "ABITstar")
OPTIMAL = ("BITstar", "ABITstar", "InformedRRTstar", "InformedRRTstar" + MATCHED)  # to the bound
SHORT = {"RRTConnect": "RRTC", "RRTConnect-m": "RRTC-m", "BITstar": "BIT*", "ABITstar": "ABIT*",
         "InformedRRTstar": "IRRT*", "InformedRRTstar-m": "IRRT*-m"}  # fmt: skip


def run_ours(grid, s, e, exact: float, seed: int, limit: float) -> dict:
    """Our default configuration, its time budget capped at ``limit`` s."""
    cfg = USER.replace(max_seconds=min(limit, USER.budgets(int((grid == 0).sum()))[1]),
                       seconds_per_free_cell=None)  # fmt: skip
    r = plan(grid, s, e, stop="optimal", reference_length=exact, seed=seed, config=cfg)
    ok = path_free(grid, r.path) and (not r.success or r.cost <= 1.01 * exact + 1e-9)
    return {"first": r.time_to_first, "stop": r.time_to_stop if r.success else math.nan,
            "clipped": not ok}  # fmt: skip


def run_native(native, grid, s, e, bound: float, limit: float, name: str) -> dict:
    """OMPL's ``name`` (with :data:`MATCHED`: its range our Steer step) to ``bound`` px."""
    step = USER.eta if name.endswith(MATCHED) else 0.0
    r = native.solve(name.removesuffix(MATCHED), s, e, bound, limit, step)
    clipped = len(r.path) > 0 and not path_free(grid, r.path)
    return {"first": r.first, "stop": r.stop, "clipped": clipped}


def bench_map(native, name: str, longest: int, seeds: int, limit: float) -> dict:
    """``{planner: [run, ...]}`` over the map's queries and seeds (runs in the same order)."""
    grid, chosen = queries(name, longest)
    native.set_map(grid)
    runs: dict[str, list[dict]] = {}
    for q in chosen:
        s, e = q.start_point, q.goal_point
        exact = any_angle_length(grid, s, e)
        for seed in range(seeds):
            runs.setdefault("ours", []).append(run_ours(grid, s, e, exact, seed, limit))
            for planner in dict.fromkeys(FIRST + OPTIMAL):
                r = run_native(native, grid, s, e, 1.01 * exact, limit, planner)
                runs.setdefault(planner, []).append(r)
    return runs


def median(runs: list[dict], key: str, limit: float) -> tuple[float, bool]:
    """Median seconds to ``key`` (unsolved at ``limit``) and whether it is a lower bound."""
    times = sorted(r[key] if not math.isnan(r[key]) else math.inf for r in runs)
    m = statistics.median(times)
    return (limit, True) if math.isinf(m) else (m, False)


def cell(value: float, lower: bool, width: int = 9) -> str:
    return f"{('>' if lower else '') + f'{value * 1e3:.3g}':>{width}}"


def paired(ours: list[dict], theirs: list[dict], key: str) -> str:
    """Median of theirs / ours over the runs both solved (ours unsolved: none here)."""
    ratios = [t[key] / o[key] for o, t in zip(ours, theirs, strict=True)
              if not math.isnan(t[key]) and not math.isnan(o[key]) and o[key] > 0]  # fmt: skip
    return f"{statistics.median(ratios):.3g}x ({len(ratios)})" if ratios else "-"


def section(per_map: dict, key: str, names: tuple, limit: float) -> list[str]:
    """The table to ``key`` ('first' or 'stop') over ``names`` (OMPL's) beside ours."""
    head = (f"{'map':<11}{'ours':>8}" + "".join(f"{SHORT[n]:>8}" for n in names)
            + f"{'ours ms':>11}" + "".join(f"{SHORT[n] + ' ms':>11}" for n in names)
            + f"{'best':>8}{'ratio':>9}{'paired':>12}  clipped")  # fmt: skip
    lines = [head]
    for name, runs in per_map.items():
        n = len(runs["ours"])
        solved = [sum(not math.isnan(r[key]) for r in runs[p]) for p in ("ours", *names)]
        meds = {p: median(runs[p], key, limit) for p in ("ours", *names)}
        wins = dict(zip(("ours", *names), solved, strict=True))
        best = min(names, key=lambda p: (meds[p][0], -wins[p], p))  # ties: the most solved
        (o, ol), (b, bl) = meds["ours"], meds[best]
        ratio = f"{'>' if bl else ''}{b / o:.3g}x" if o > 0 and not ol else "-"
        line = f"{name:<11}" + "".join(f"{f'{k}/{n}':>8}" for k in solved)
        line += "".join(cell(*meds[p], 11) for p in ("ours", *names))
        line += f"{SHORT[best]:>8}{ratio:>9}{paired(runs['ours'], runs[best], key):>12}  "
        line += "/".join(str(sum(r["clipped"] for r in runs[p])) for p in ("ours", *names))
        lines.append(line)
    return lines


def unclipped(per_map: dict) -> dict:
    """``per_map`` with every clipped run counted as unsolved (no first solution, no stop;
    for the stop only: a run's final path is the one that reached the bound)."""
    lost = {"first": math.nan, "stop": math.nan}
    return {m: {p: [r | lost if r["clipped"] else r for r in rs] for p, rs in runs.items()}
            for m, runs in per_map.items()}  # fmt: skip


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--limit", type=float, default=5.0, help="seconds per query, every planner")
    ap.add_argument("--longest", type=int, default=5)
    ap.add_argument("--seeds", type=int, default=3)
    ap.add_argument("--maps", nargs="+", default=list(MAPS), choices=MAPS)
    ap.add_argument("--out", type=Path, default=ROOT / "benchmarks/results/bench_movingai_ompl.txt")
    args = ap.parse_args(argv)
    binary = ompl_native.build_or_explain()
    if binary is None:
        return 2
    code = machine()
    warmup()
    load = os.getloadavg()
    per_map = {}
    with ompl_native.Harness(binary, seed=1) as native:
        for name in args.maps:
            per_map[name] = bench_map(native, name, args.longest, args.seeds, args.limit)
            print(f"{name}: done", flush=True)
    clipped = {p: sum(r["clipped"] for runs in per_map.values() for r in runs[p])
               for p in next(iter(per_map.values()))}  # fmt: skip
    clipped = ", ".join(f"{SHORT.get(p, p)} {k}" for p, k in clipped.items() if k) or "none"
    after = os.getloadavg()
    lines = [f"# {code}",
             f"# {args.longest} longest queries x {args.seeds} seeds per map; ours: plan()'s "
             f"default (conf/planner/user.yaml) vs native OMPL 1.5 at OMPL's defaults and (-m) "
             f"with our Steer step, {USER.eta:g} px, as its range; "
             f"{args.limit:g} s per query each; times in ms (> : a lower bound, the median "
             "run unsolved); ratio: best OMPL median / ours; paired: median of OMPL's best / "
             "ours over the runs it solved (count)",
             f"# 1-min load average {load[0]:.2f} before, {after[0]:.2f} after; clipped "
             f"paths (crossing an obstacle cell; still counted): {clipped}",
             "", "first solution (OMPL: RRT-Connect, RRT-Connect-m, BIT*, ABIT*)",
             *section(per_map, "first", FIRST, args.limit),
             "", "to 1.01 x the exact optimum (OMPL: BIT*, ABIT*, Informed RRT*, Informed RRT*-m)",
             *section(per_map, "stop", OPTIMAL, args.limit),
             "", "to 1.01 x the exact optimum, a run whose path crosses an obstacle cell "
             "counted as unsolved",
             *section(unclipped(per_map), "stop", OPTIMAL, args.limit)]  # fmt: skip
    print("\n".join(lines))
    from vnrrt.infra.io import write_text

    write_text(args.out, "\n".join(lines) + "\n")
    print(f"written: {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
