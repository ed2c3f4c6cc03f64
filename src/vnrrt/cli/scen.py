"""``vnrrt plan --map M.map --scen M.map.scen``: plan a batch of MovingAI scenarios
(:mod:`vnrrt.maps.movingai`), one printed row per query and a summary line.

Queries are picked from the file (``--scen-rows``: indices in file order, 0-based, e.g.
``0,5,10-19``; ``--longest N``: the N with the longest published optimal lengths), then the
first ``--limit`` of them are planned, in file order. Each starts and ends at its cells'
centres. A query with an endpoint on an obstacle of the map (older files made for another
version of it) is listed as skipped, not planned.
"""

from __future__ import annotations

import argparse
import statistics
from pathlib import Path

import numpy as np

from vnrrt.cli.inputs import UsageError
from vnrrt.cli.stage import EXIT_BUDGET, EXIT_OK

COLUMNS = f"{'line':>6} {'bucket':>6} {'start':>11} {'goal':>11} {'solved':>6} {'cost':>9} " \
          f"{'optimal':>9} {'time_ms':>9}"  # fmt: skip


def add_scen_arguments(p: argparse.ArgumentParser) -> None:
    """``--scen``, ``--scen-rows``, ``--longest``, ``--limit`` of ``vnrrt plan``."""
    p.add_argument("--scen", type=Path, help="MovingAI .scen file: plan its queries on --map")
    p.add_argument("--scen-rows", help="with --scen: query indices in file order, e.g. 0,5,10-19")
    p.add_argument("--longest", type=int, help="with --scen: the N longest queries")
    p.add_argument("--limit", type=int, help="with --scen: at most N queries (the first ones)")


def parse_rows(text: str, n: int) -> list[int]:
    """Indices ``0 <= i < n`` of ``'0,5,10-19'`` (ranges inclusive), sorted, no repeats."""
    rows: set[int] = set()
    for part in text.split(","):
        lo, dash, hi = part.strip().partition("-")
        if not lo.isdigit() or (dash and not hi.isdigit()):
            raise UsageError(f"--scen-rows {text!r}: expected indices and ranges like 0,5,10-19")
        first, last = int(lo), int(hi) if dash else int(lo)
        if first > last or last >= n:
            raise UsageError(f"--scen-rows {part.strip()!r}: not a range in [0, {n}) of the "
                             "file's queries")  # fmt: skip
        rows.update(range(first, last + 1))
    return sorted(rows)


def pick(scenarios: list, rows: str | None, longest: int | None, limit: int | None) -> list:
    """The queries ``--scen-rows``/``--longest``/``--limit`` select, in file order."""
    for name, value in (("--longest", longest), ("--limit", limit)):
        if value is not None and value < 1:
            raise UsageError(f"{name} {value}: must be at least 1")
    index = parse_rows(rows, len(scenarios)) if rows else list(range(len(scenarios)))
    if longest is not None:
        by_length = sorted(index, key=lambda i: (-scenarios[i].optimal, i))
        index = sorted(by_length[:longest])
    return [scenarios[i] for i in index[:limit]]


def _heat(args, grid: np.ndarray, s):
    """The ``--checkpoint`` network's heatmap of query ``s``, or None without one (or for
    RRT*, which samples none)."""
    if not args.checkpoint or args.planner == "rrt_star":
        return None
    from vnrrt.data.targets import PLANNER_TARGETS
    from vnrrt.predict import heatmap

    target = PLANNER_TARGETS[args.planner]  # a network of the target the planner samples
    return heatmap(args.checkpoint, grid, s.start, s.goal, target=target, pad=args.pad)


def run_scen(args: argparse.Namespace, cfg, label: str) -> int:
    """Plan the selected queries of ``args.scen`` on ``args.map``; print a row for each and
    a summary naming the configuration (``label``) and its budget on the map; 0 when every
    planned query met the stop rule, else 1 (a budget was hit)."""
    from vnrrt.maps.movingai import blocked_endpoint, check_scenarios, read_map, read_scen
    from vnrrt.planners import plan

    for flag in ("start", "goal", "heatmap", "out", "instance"):
        if getattr(args, flag) is not None:
            raise UsageError(f"--{flag} does not go with --scen (each query has its own)")
    if args.map.suffix != ".map":
        raise UsageError(f"--scen needs a MovingAI .map file as --map, not {args.map}")
    if not args.scen.is_file():
        raise UsageError(f"scenario file {args.scen} not found")
    if args.planner != "rrt_star" and not args.checkpoint:
        raise UsageError(f"--planner {args.planner} with --scen needs --checkpoint CKPT")
    grid = read_map(args.map)
    scenarios = read_scen(args.scen)
    check_scenarios(grid, scenarios, str(args.scen))
    chosen = pick(scenarios, args.scen_rows, args.longest, args.limit)
    print(COLUMNS)
    times, solved, skipped = [], 0, 0
    for s in chosen:
        cells = f"{s.bucket:>6} {str(s.start).replace(' ', ''):>11} " \
                f"{str(s.goal).replace(' ', ''):>11}"  # fmt: skip
        why = blocked_endpoint(grid, s)
        if why is not None:
            skipped += 1
            print(f"{s.line:>6} {cells} skipped: {why.split(': ', 1)[1]}")
            continue
        result = plan(grid, s.start_point, s.goal_point, args.planner,
                      heatmap=_heat(args, grid, s), stop=args.stop, seed=args.seed,
                      config=cfg)  # fmt: skip
        solved += bool(result.success)
        times.append(result.time_to_stop * 1e3)
        print(f"{s.line:>6} {cells} {'yes' if result.success else 'no':>6} "
              f"{result.cost:>9.3f} {s.optimal:>9.3f} {times[-1]:>9.2f}")  # fmt: skip
    median = f"{statistics.median(times):.2f} ms" if times else "n/a"
    iterations, seconds = cfg.budgets(int(np.count_nonzero(grid == 0)))
    print(f"summary: solved {solved} of {len(times)} planned ({skipped} skipped) of "
          f"{len(scenarios)} in {args.scen}; median time {median}; planner {args.planner}, "
          f"stop {args.stop}, budget {iterations} iterations / {seconds:g} s, "
          f"config {label}")  # fmt: skip
    return EXIT_OK if solved == len(times) else EXIT_BUDGET
