"""Benchmark: the evaluation's trials stage, in planner trials per second per core, and what the
paper scale's trial count then costs on this machine's cores and on a cluster.

Runs the trials stage's own code (:func:`vnrrt.evaluation.trials.run_trials`, one worker: one
core) with the paper's planner configurations and stop rules (``scale=paper``: every planner,
the M-VNRRT* thresholds, informed variants, the A* and exact-optimum stops) on instances made
here from the data generator's random maps and the five named maps. Trained networks' heatmaps
are not available here: each network source samples the oracle heatmap of its target (the
labels' path for NRRT*, the interior vertices for VNRRT*/M-VNRRT*), so the heatmap planners
run at the rate of a perfect network. Per trial the stage's wall time (heatmap and sampler
set-up, the ``plan()`` call, the row) and the planning time alone are both reported; the
paper-scale cost takes the paper protocol's jobs (:func:`vnrrt.evaluation.protocol.trial_jobs`
over its 5 named and ``eval.random_maps`` random instances), each trial at the mean planning
time measured here for its map kind, stop rule and configuration, scaled by the measured
wall / planning ratio.

    python benchmarks/bench_trials.py [--random-maps 12] [--named-trials 4] [--cluster 64,256]
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from bench_paper_scale import fmt_time, trial_seconds
from vnrrt.config import compose, section
from vnrrt.data.instances import EvalInstance
from vnrrt.evaluation.config import EvalConfig
from vnrrt.evaluation.oracles import instance_heatmap
from vnrrt.evaluation.protocol import configurations, trial_counts, trial_jobs
from vnrrt.evaluation.trials import LIBRARY_SETTINGS, TrialSettings, run_trials
from vnrrt.maps.config import DataConfig
from vnrrt.maps.generate import generate_map, map_rng
from vnrrt.maps.named import NAMES, named_map
from vnrrt.planners import PlannerConfig, any_angle_path, taut_length, warmup
from vnrrt.search import astar, path_vertices

ORACLE = {"path": "oracle_path", "interior_vertices": "oracle_vertex"}  # network target -> oracle
HEAT = LIBRARY_SETTINGS  # the oracles' blur and floor, the mass radii: the library's


def instance(i: int, map_set: str, grid, start, goal, sources: dict[str, str]) -> EvalInstance:
    """An evaluation instance of ``grid`` between cells ``start`` and ``goal`` whose network
    sources (name -> target) hold the oracle heatmap of their target."""
    path, length = astar(grid, start, goal)
    s, g = (start[0] + 0.5, start[1] + 0.5), (goal[0] + 0.5, goal[1] + 0.5)
    exact_path, exact = any_angle_path(grid, s, g)
    inst = EvalInstance(i, (0, i), map_set, map_set, 0, grid, tuple(start), tuple(goal), length,
                        exact, taut_length(grid, s, g), path, path_vertices(path),
                        exact_path)  # fmt: skip
    free = grid == 0
    inst.heatmaps.update({n: instance_heatmap(ORACLE[t], inst, HEAT.sigma, HEAT.floor, free)
                          for n, t in sources.items()})  # fmt: skip
    return inst


def instances(n_random: int, sources: dict[str, str]) -> list[EvalInstance]:
    """The five named maps (their own endpoints) and ``n_random`` generator maps (their first
    start and goal)."""
    out = []
    for i, name in enumerate(NAMES):
        fm = named_map(name, 200)
        out.append(instance(i, name, fm.grid, fm.starts[0], fm.goals[0], sources))
    for i in range(n_random):
        fm = generate_map(map_rng(12345, i), DataConfig(size=200))
        out.append(instance(len(out), "random", fm.grid, fm.starts[0], fm.goals[0], sources))
    return out


def paper_cost(cfg, specs, table) -> tuple[float, int]:
    """Planning seconds and trial count of the paper protocol's jobs, each trial at the mean
    planning time of its (map kind, stop rule, configuration) in ``table``."""
    ev = section(cfg, "eval", EvalConfig)
    kinds = ["named"] * len(NAMES) + ["random"] * ev.random_maps
    rate = trial_seconds(table)
    jobs = trial_jobs(kinds, specs, trial_counts(ev))
    seconds = sum(j.count * rate[kinds[j.instance], j.stop, j.key.text] for j in jobs)
    return float(seconds), sum(j.count for j in jobs)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--random-maps", type=int, default=12, help="random instances")
    ap.add_argument("--named-trials", type=int, default=4, help="trials per named map and stop")
    ap.add_argument("--cluster", default="64,256", help="cluster sizes (cores) to cost")
    args = ap.parse_args()
    cfg = compose(["scale=paper"])
    ev, planner = section(cfg, "eval", EvalConfig), section(cfg, "planner", PlannerConfig)
    specs = configurations(ev, planner.taus, planner.tau)
    targets = {"nrrtnet": "path", "vertexnet": "interior_vertices"}
    sources = {n: targets[n] for n in set(ev.sources.values())}
    insts = instances(args.random_maps, sources)
    k = args.named_trials
    counts = {("named", "initial"): k, ("named", "optimal"): k,
              ("named", "optimal_any_angle"): k, ("random", "initial"): 1,
              ("random", "optimal"): 1, ("random", "optimal_any_angle"): 1}  # fmt: skip
    warmup()
    heat = TrialSettings(HEAT.radius, HEAT.endpoint_radius, targets, HEAT.sigma, HEAT.floor)
    t0 = time.perf_counter()
    table = run_trials(insts, specs, counts, seed=0, workers=1, config=planner, heat=heat)
    wall = time.perf_counter() - t0
    planning = float(table["time_to_stop"].sum())
    n = len(table)
    print(
        f"{n:,} trials of {len(specs)} configurations on {len(insts)} instances, one core: "
        f"{wall:.1f} s wall, {n / wall:.1f} trials/s per core ({1e3 * wall / n:.2f} ms a "
        f"trial; planning alone {1e3 * planning / n:.2f} ms, {n / planning:.1f} trials/s)"
    )
    for stop, part in table.groupby("stop"):
        print(f"  {stop}: {len(part):,} trials, planning {1e3 * part['time_to_stop'].mean():.2f}"
              f" ms a trial, success {part['success'].mean():.3f}")  # fmt: skip
    seconds, count = paper_cost(cfg, specs, table)
    seconds *= wall / planning  # from planning time to the stage's wall time
    print(f"paper scale: {count:,} trials, {seconds / 3600:.2f} core-hours at these rates "
          f"({count / seconds:.1f} trials/s per core)")  # fmt: skip
    for cores in [2, *(int(c) for c in args.cluster.split(","))]:
        print(f"  on {cores} cores: {fmt_time(seconds / cores)}")
    print(
        f"  (planning-time share of the wall time: {planning / wall:.2f}; "
        f"median trial {1e3 * np.median(table['time_to_stop']):.2f} ms)"
    )


if __name__ == "__main__":
    main()
