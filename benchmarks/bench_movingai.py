"""Benchmark: our planner on the shipped MovingAI maps (``data/movingai/``): the default of
``plan()`` and ``vnrrt plan`` (:data:`vnrrt.planners.USER`, ``conf/planner/user.yaml``: our
fastest settings, budgets scaled with the map's free cells) beside the paper's protocol
(:meth:`PlannerConfig.paper`, the study's ``planner=default``) and
:data:`vnrrt.planners.FASTEST` (the default's settings at fixed budgets).

Per map, the ``--longest`` queries with the longest published optimal lengths (queries with
an endpoint on an obstacle left out: ``losttemple``'s older file has 56), from their cells'
centres, ``--seeds`` seeds each, RRT* stopping at 1.01 x the exact any-angle optimum
(:func:`vnrrt.search.any_angle_length`) or at the configuration's budget on the map (the
paper's and FASTEST's 200,000 iterations or 30 s; the default's by its rule, printed). These
queries were not used to choose the default's budget rule (``select_budget.py``). Reported
per map and configuration: runs solved, the median of the planner's own
time to stop (``time_to_stop``) over solved runs and over all runs (an unsolved run counts
with its time to the budget: a lower bound), and the median whole ``plan()`` call over all
runs. Kernels are compiled before timing (:func:`vnrrt.planners.warmup`). The machine's
cores may be shared: the header records the load average before and after.

    python benchmarks/bench_movingai.py [--longest 5] [--seeds 3]
        [--maps arena lak304d 64room_000 losttemple] [--out benchmarks/results/bench_movingai.txt]
"""

from __future__ import annotations

import argparse
import os
import platform
import statistics
import subprocess
import sys
import time
from pathlib import Path

from vnrrt.maps.movingai import blocked_endpoint, read_map, read_scen
from vnrrt.planners import FASTEST, USER, PlannerConfig, plan, warmup
from vnrrt.search import any_angle_length

ROOT = Path(__file__).resolve().parents[1]
DATA = ROOT / "data" / "movingai"
MAPS = ("arena", "lak304d", "64room_000", "losttemple")
CONFIGS = {"paper": PlannerConfig.paper(), "user": USER, "fastest": FASTEST}


def machine() -> str:
    """CPU model, cores, Python, and the code (commit, and whether the tree has changes)."""
    cpu = platform.processor() or platform.machine()
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    git = ["git", "-C", str(ROOT)]
    head = subprocess.run([*git, "rev-parse", "--short", "HEAD"], capture_output=True,
                          text=True).stdout.strip() or "unknown"  # fmt: skip
    dirty = subprocess.run([*git, "status", "--porcelain", "--untracked-files=no"],
                           capture_output=True, text=True).stdout.strip()  # fmt: skip
    return (f"{cpu}, {os.cpu_count()} cores, Python {platform.python_version()}; code "
            f"{head}{' with uncommitted changes' if dirty else ''}")  # fmt: skip


def queries(name: str, longest: int) -> tuple:
    """The map's grid and its ``longest`` plannable queries, longest published length first."""
    grid = read_map(DATA / f"{name}.map")
    scen = [s for s in read_scen(DATA / f"{name}.map.scen") if blocked_endpoint(grid, s) is None]
    return grid, sorted(scen, key=lambda s: (-s.optimal, s.line))[:longest]


def runs(grid, chosen, cfg: PlannerConfig, seeds: int) -> list[tuple[bool, float, float]]:
    """``(solved, time_to_stop, plan() call seconds)`` of each query and seed (the budget:
    each result's, checked to be the configuration's on this map)."""
    budget = cfg.budgets(int((grid == 0).sum()))
    out = []
    for s in chosen:
        exact = any_angle_length(grid, s.start_point, s.goal_point)
        for seed in range(seeds):
            t0 = time.perf_counter()
            r = plan(grid, s.start_point, s.goal_point, stop="optimal", reference_length=exact,
                     seed=seed, config=cfg)  # fmt: skip
            out.append((bool(r.success), r.time_to_stop, time.perf_counter() - t0))
            assert r.budget == budget, (r.budget, budget)
    return out


def row(name: str, config: str, results: list, budget: tuple[int, float]) -> str:
    solved = [t for ok, t, _ in results if ok]
    med = f"{statistics.median(solved) * 1e3:10.2f}" if solved else f"{'-':>10}"
    every = statistics.median(t for _, t, _ in results) * 1e3
    call = statistics.median(c for *_, c in results) * 1e3
    return (f"{name:<11} {config:<8} {len(solved):>3}/{len(results):<3} {med} {every:10.2f} "
            f"{call:10.2f} {budget[0]:>10} {budget[1]:>6.1f}")  # fmt: skip


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--longest", type=int, default=5)
    ap.add_argument("--seeds", type=int, default=3)
    ap.add_argument("--maps", nargs="+", default=list(MAPS), choices=MAPS)
    ap.add_argument("--out", type=Path, default=ROOT / "benchmarks/results/bench_movingai.txt")
    args = ap.parse_args(argv)
    code = machine()  # before the runs: the code they run
    warmup()
    load = os.getloadavg()
    lines = [f"{'map':<11} {'config':<8} {'solved':<7} {'med_ok_ms':>10} {'med_all_ms':>10} "
             f"{'call_ms':>10} {'budget_it':>10} {'_s':>6}"]  # fmt: skip
    print(lines[0], flush=True)
    for name in args.maps:
        grid, chosen = queries(name, args.longest)
        for config, cfg in CONFIGS.items():
            budget = cfg.budgets(int((grid == 0).sum()))
            lines.append(row(name, config, runs(grid, chosen, cfg, args.seeds), budget))
            print(lines[-1], flush=True)
    after = os.getloadavg()
    head = [f"# {code}",
            f"# {args.longest} longest queries x {args.seeds} seeds per map, RRT* to 1.01 x the "
            "exact any-angle optimum; times in ms (med_ok: solved runs; med_all: every run, "
            "unsolved at its budget; call: the whole plan() call); budget: iterations and seconds "
            "on the map; user: the default of plan() and vnrrt plan, paper: the study's",
            f"# 1-min load average {load[0]:.2f} before, {after[0]:.2f} after"]  # fmt: skip
    from vnrrt.infra.io import write_text

    write_text(args.out, "\n".join([*head, *lines]) + "\n")
    print(f"written: {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
