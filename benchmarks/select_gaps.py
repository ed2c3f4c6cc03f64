"""Selection of the gap sampler's settings for our best configuration, on the development maps.

The gap sampler (``PlannerConfig.gap_share``, ``gap_width``, ``gap_after``;
:mod:`vnrrt.planners.gaps`) is chosen here and only here, on the development maps of the
planner benchmark (:func:`planner_maps.dev_instances`) with seeds that the benchmark does not
use; the held-out maps are never run. Every candidate is the committed best configuration
(:data:`vnrrt.planners.FASTEST` with ``gap_share=0``, the baseline) with one grid point of
the three settings. Per map and candidate: the median, over ``--trials`` runs, of the run's
time to a cost within 1% of the exact optimum (a miss counts as ``--time-limit``); per
candidate: the geometric mean over maps of the speed-up against the baseline (the
selection criterion), its worst map and the number of maps where it is slower. Runs of
all candidates alternate per trial, so the machine's drift falls on all of them alike.
Two rounds: every candidate with ``--trials`` runs, then the ``--confirm`` best of them and
the baseline again with ``--confirm-trials`` runs on other seeds; the best of the second
round is selected (the first round's top scores lie within its noise of each other).
``--held-out`` runs nothing of the above: it reports the committed choice (``FASTEST``)
against the baseline on the held-out maps, once, after the selection.

    python benchmarks/select_gaps.py [--trials 9] [--confirm 4] [--confirm-trials 25]
    python benchmarks/select_gaps.py --held-out [--confirm-trials 25]
"""

from __future__ import annotations

import argparse
import itertools
import math
import sys

import numpy as np

from planner_maps import dev_instances, held_out_instances
from vnrrt.planners import FASTEST, any_angle_path, path_free, plan, warmup

SHARES, WIDTHS, AFTERS = (0.1, 0.2, 0.3, 0.5), (4, 8, 16), (0, 256, 1024)
SEED = 7  # the benchmark's runs use seed 0


def candidates() -> dict:
    """``{label: config}``: the baseline (no gap draws) and every grid point."""
    base = FASTEST.replace(gap_share=0.0)
    out = {"baseline": base}
    for share, width, after in itertools.product(SHARES, WIDTHS, AFTERS):
        label = f"share {share} width {width} after {after}"
        out[label] = base.replace(gap_share=share, gap_width=width, gap_after=after)
    return out


def run_map(g, s, e, configs: dict, trials: int, limit: float, seed: tuple) -> dict:
    """``{label: median seconds to 1%}`` on one instance (every path checked)."""
    exact = any_angle_path(g, s, e)[1]
    times: dict[str, list[float]] = {label: [] for label in configs}
    for k in range(trials):
        for label, cfg in configs.items():
            r = plan(g, s, e, stop="optimal", reference_length=exact, seed=(*seed, k),
                     config=cfg)  # fmt: skip
            if not path_free(g, r.path) or (r.success and r.cost > 1.01 * exact + 1e-9):
                raise AssertionError(f"{label}: a path fails the exact test or the stop rule")
            times[label].append(r.time_to_stop if r.success else limit)
    return {label: float(np.median(t)) for label, t in times.items()}


def score(configs: dict, trials: int, limit: float, seed: int, maps=dev_instances) -> dict:
    """One round on every map of ``maps`` (the development set): prints the per-map medians
    and each candidate's speed-ups; returns ``{label: geometric mean speed-up}``."""
    per_map = {}
    for m, (name, g, s, e) in enumerate(maps()):
        per_map[name] = run_map(g, s, e, configs, trials, limit, (seed, m))
        row = " ".join(f"{1e3 * per_map[name][k]:.3g}" for k in configs)
        print(f"{name:<15} ms: {row}", flush=True)
    print(f"\n{len(per_map)} maps ({maps.__name__}), {trials} trials; speed-up = baseline / "
          "candidate, median time to 1% of the exact optimum per map")  # fmt: skip
    scores = {}
    for label in configs:
        ratios = np.array([m["baseline"] / m[label] for m in per_map.values()])
        scores[label] = math.exp(np.mean(np.log(ratios)))
        worst = min(per_map, key=lambda n: per_map[n]["baseline"] / per_map[n][label])
        print(
            f"{label:<30} geometric mean {scores[label]:5.2f}x  median {np.median(ratios):5.2f}x"
            f"  worst {ratios.min():5.2f}x ({worst})  slower on {int((ratios < 1).sum())}"
        )
    return scores


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--trials", type=int, default=9, help="runs per map and candidate")
    ap.add_argument("--confirm", type=int, default=4, help="candidates in the second round")
    ap.add_argument("--confirm-trials", type=int, default=25, help="runs in the second round")
    ap.add_argument("--time-limit", type=float, default=2.0, help="seconds per run")
    ap.add_argument("--held-out", action="store_true", help="report FASTEST on held-out maps")
    args = ap.parse_args(argv)
    configs = {k: c.replace(max_seconds=args.time_limit) for k, c in candidates().items()}
    warmup()
    if args.held_out:
        chosen = {"baseline": configs["baseline"], "FASTEST": FASTEST.replace(
            max_seconds=args.time_limit)}  # fmt: skip
        score(chosen, args.confirm_trials, args.time_limit, SEED + 2, held_out_instances)
        return 0
    print("round 1: every candidate (columns in the order of the lines below)")
    first = score(configs, args.trials, args.time_limit, SEED)
    top = sorted((k for k in first if k != "baseline"), key=first.get, reverse=True)
    kept = {k: configs[k] for k in ["baseline", *top[: args.confirm]]}
    print(f"\nround 2: the baseline and the {args.confirm} best of round 1, other seeds")
    second = score(kept, args.confirm_trials, args.time_limit, SEED + 1)
    best = max((k for k in second if k != "baseline"), key=second.get)
    print(f"\nselected: {best} ({second[best]:.2f}x the baseline, geometric mean over maps)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
