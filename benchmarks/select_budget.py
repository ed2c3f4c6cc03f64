"""Selection of the budget rule of the user default (``conf/planner/user.yaml``) on MovingAI
scenarios that the reporting benchmark (``bench_movingai.py``: the 5 longest per map) never
runs.

Per shipped map, the selection queries are the ``--next`` longest after the ``--skip``
longest (the reported ones), and ``--spread`` more taken evenly over the rest of the file
in length order (short and middle buckets); ``--seeds`` seeds each, seeds the reporting
benchmark does not use. Every run is the user default's planner settings
(:data:`vnrrt.planners.FASTEST`'s) with budgets far above any rule's (``--cap-seconds``),
stopping at 1.01 x the exact any-angle optimum; per run, the iterations and seconds it
needed per free cell of its map. The rule's constants follow mechanically, fixed before
the runs: the budget is ``max(floor, k x free cells)`` (floors: FASTEST's fixed budgets),
with ``iterations_per_free_cell`` ``--margin-iterations`` x the most iterations per free cell
that a solved selection run needed, and ``seconds_per_free_cell`` ``--margin-seconds`` x the
most seconds per free cell (time is the machine-dependent backstop, hence its wider margin),
each rounded up to 1, 2 or 5 x a power of ten (:func:`constant`).

    python benchmarks/select_budget.py [--skip 5] [--next 20] [--spread 10] [--seeds 3]
"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

import numpy as np

from bench_movingai import DATA, MAPS, machine
from vnrrt.maps.movingai import blocked_endpoint, read_map, read_scen
from vnrrt.planners import FASTEST, plan, warmup
from vnrrt.search import any_angle_length

ROOT = Path(__file__).resolve().parents[1]
FIRST_SEED = 100  # the reporting benchmarks use seeds 0, 1, 2


def selection(name: str, skip: int, following: int, spread: int) -> tuple:
    """The map's grid and its selection queries: the ``following`` longest after the
    ``skip`` longest, and ``spread`` evenly spaced over the rest (longest first)."""
    grid = read_map(DATA / f"{name}.map")
    scen = [s for s in read_scen(DATA / f"{name}.map.scen")
            if blocked_endpoint(grid, s) is None and s.start != s.goal]  # fmt: skip
    ranked = sorted(scen, key=lambda s: (-s.optimal, s.line))
    rest = ranked[skip + following :]
    picks = np.linspace(0, len(rest) - 1, spread).round().astype(int) if rest else []
    return grid, ranked[skip : skip + following] + [rest[i] for i in sorted(set(picks))]


def nice_ceiling(x: float) -> float:
    """The least of 1, 2 or 5 x a power of ten that is at least ``x`` (> 0)."""
    power = 10.0 ** math.floor(math.log10(x))
    return next(m * power for m in (1, 2, 5, 10) if m * power >= x * (1 - 1e-12))


def needs(grid, chosen, seeds: int, cap: float) -> list[tuple[bool, int, float]]:
    """``(solved, iterations, seconds)`` of each run."""
    cfg = FASTEST.replace(max_iterations=2**40, max_seconds=cap)
    out = []
    for s in chosen:
        exact = any_angle_length(grid, s.start_point, s.goal_point)
        for seed in range(FIRST_SEED, FIRST_SEED + seeds):
            r = plan(grid, s.start_point, s.goal_point, stop="optimal", reference_length=exact,
                     seed=seed, config=cfg)  # fmt: skip
            out.append((bool(r.success), r.iterations, r.time_to_stop))
    return out


def constant(runs: list[tuple[int, float]], margin: float) -> float:
    """The per-cell constant: ``margin`` x the largest need per free cell of ``runs``
    (``(free cells, need)`` pairs), rounded up by :func:`nice_ceiling`."""
    return nice_ceiling(margin * max(x / free for free, x in runs))


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--skip", type=int, default=5)
    ap.add_argument("--next", type=int, default=20)
    ap.add_argument("--spread", type=int, default=10)
    ap.add_argument("--seeds", type=int, default=3)
    ap.add_argument("--cap-seconds", type=float, default=60.0)
    ap.add_argument("--margin-iterations", type=float, default=4.0)
    ap.add_argument("--margin-seconds", type=float, default=10.0)
    ap.add_argument("--out", type=Path, default=ROOT / "benchmarks/results/select_budget.txt")
    args = ap.parse_args(argv)
    lines = [f"# {machine()}",
             f"# selection: per map the {args.next} longest queries after the {args.skip} "
             f"longest, {args.spread} spread over the rest; seeds {FIRST_SEED}.."
             f"{FIRST_SEED + args.seeds - 1}; FASTEST's settings to 1.01 x the exact optimum",
             f"{'map':<11} {'free':>7} {'runs':>5} {'solved':>6} {'iters med':>10} "
             f"{'iters max':>10} {'ms med':>8} {'ms max':>8}"]  # fmt: skip
    warmup()
    iters, secs = [], []
    for name in MAPS:
        grid, chosen = selection(name, args.skip, args.next, args.spread)
        free = int(np.count_nonzero(grid == 0))
        runs = needs(grid, chosen, args.seeds, args.cap_seconds)
        it = [i for ok, i, _ in runs if ok]
        ms = [t * 1e3 for ok, _, t in runs if ok]
        iters += [(free, i) for i in it]
        secs += [(free, t / 1e3) for t in ms]
        lines.append(f"{name:<11} {free:>7} {len(runs):>5} {len(it):>6} {np.median(it):>10.0f} "
                     f"{max(it):>10} {np.median(ms):>8.2f} {max(ms):>8.2f}")  # fmt: skip
        print(lines[-1], flush=True)
    floor = (FASTEST.max_iterations, FASTEST.max_seconds)
    k_it = constant(iters, args.margin_iterations)
    k_s = constant(secs, args.margin_seconds)
    lines.append(f"rule: budget = max(floor, k x free cells), floors {floor[0]} iterations and "
                 f"{floor[1]:g} s; iterations_per_free_cell {k_it:g} (margin "
                 f"{args.margin_iterations:g}), seconds_per_free_cell {k_s:g} (margin "
                 f"{args.margin_seconds:g})")  # fmt: skip
    print(lines[-1])
    from vnrrt.infra.io import write_text

    write_text(args.out, "\n".join(lines) + "\n")
    print(f"written: {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
