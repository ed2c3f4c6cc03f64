"""Benchmark: dataset labelling throughput and A* query time against scipy and skimage.

Prints, measured in this run on one core:
  * generate + label: labelled instances per second per core, and bytes per instance on
    disk (target: >= 2,000 instances/s/core, < 700 B/instance);
  * one A* query (vnrrt.search.astar) next to scipy.sparse.csgraph.dijkstra on the same
    8-connected graph and skimage.graph.MCP_Geometric on the same maps, with ratios.

Usage: python benchmarks/bench_labels.py [--maps 40] [--queries 200]
"""

from __future__ import annotations

import argparse
import os
import tempfile
import time

import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import dijkstra
from skimage.graph import MCP_Geometric

from vnrrt.data.build import build_shard, make_map
from vnrrt.data.config import LabelsConfig
from vnrrt.grid import MOVE_COSTS, MOVES
from vnrrt.maps.config import DataConfig
from vnrrt.maps.generate import generate_map, map_rng
from vnrrt.search import astar, move_masks


def csgraph_of(grid: np.ndarray) -> coo_matrix:
    """The 8-connected no-corner-cutting graph of ``grid`` as a sparse matrix."""
    masks = move_masks(grid).astype(np.int64)
    h, w = grid.shape
    rows, cols, costs = [], [], []
    ys, xs = np.mgrid[0:h, 0:w]
    for m in range(8):
        ok = (masks >> m) & 1 == 1
        rows.append((ys * w + xs)[ok])
        cols.append(((ys + MOVES[m, 1]) * w + xs + MOVES[m, 0])[ok])
        costs.append(np.full(ok.sum(), MOVE_COSTS[m]))
    return coo_matrix((np.concatenate(costs), (np.concatenate(rows), np.concatenate(cols))),
                      shape=(h * w, h * w)).tocsr()  # fmt: skip


def bench_labelling(n_maps: int) -> tuple[float, float]:
    data, labels = DataConfig(), LabelsConfig()
    make_map(10**9, 0, data, labels)  # JIT warm-up, outside the timing
    t = time.perf_counter()
    n = sum(len(make_map(m, 0, data, labels)[1].length) for m in range(n_maps))
    rate = n / (time.perf_counter() - t)
    with tempfile.TemporaryDirectory() as tmp:
        out = os.path.join(tmp, "s.npz")
        counts = build_shard(out, 0, 0, n_maps, data, labels, workers=1)
        size = os.path.getsize(out) / counts["instances"]
    return rate, size


def bench_queries(n_queries: int) -> dict[str, float]:
    rng = np.random.default_rng(0)
    maps = [generate_map(map_rng(0, m), DataConfig()) for m in range(n_queries // 12 + 1)]
    queries = []
    for fm in maps:
        for k in range(12):
            queries.append((fm.grid, fm.starts[k], fm.goals[int(rng.integers(12))]))
    queries = queries[:n_queries]
    astar(*queries[0])  # JIT warm-up
    times = {"vnrrt A*": 0.0, "scipy dijkstra": 0.0, "skimage MCP": 0.0}
    for grid, s, g in queries:
        t0 = time.perf_counter()
        _, length = astar(grid, s, g)
        t1 = time.perf_counter()
        graph = csgraph_of(grid)  # graph build counted: the baseline needs it per map
        d = dijkstra(graph, indices=int(s[1] * grid.shape[1] + s[0]))
        t2 = time.perf_counter()
        cost = np.where(grid == 0, 1.0, np.inf)
        MCP_Geometric(cost, fully_connected=True).find_costs([(s[1], s[0])], [(g[1], g[0])])
        t3 = time.perf_counter()
        assert abs(d[g[1] * grid.shape[1] + g[0]] - length) < 1e-9
        times["vnrrt A*"] += t1 - t0
        times["scipy dijkstra"] += t2 - t1
        times["skimage MCP"] += t3 - t2
    return {k: v / len(queries) for k, v in times.items()}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--maps", type=int, default=40)
    parser.add_argument("--queries", type=int, default=200)
    args = parser.parse_args()
    rate, size = bench_labelling(args.maps)
    print(f"generate+label: {rate:,.0f} instances/s/core over {args.maps} maps "
          f"(target >= 2,000; ratio {rate / 2000:.2f}x)")  # fmt: skip
    print(f"paper scale (1.44M instances): {1.44e6 / rate / 60:.1f} core-minutes")
    print(f"disk: {size:.1f} bytes/instance (target < 700); paper scale "
          f"{size * 1.44e6 / 1e6:.0f} MB")  # fmt: skip
    per = bench_queries(args.queries)
    base = per["vnrrt A*"]
    for name, t in per.items():
        print(f"{name:15s} {t * 1e3:8.3f} ms/query  ({t / base:6.1f}x vnrrt A*)")
    print(
        f"amortised labeller: {1e3 / rate:.3f} ms/instance "
        f"({per['scipy dijkstra'] * rate:.0f}x faster than one scipy query per instance)"
    )


if __name__ == "__main__":
    main()
