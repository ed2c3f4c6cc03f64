"""Measurement behind ``labels.tie_break``: how far the A* label's interior vertices lie from
where the exact continuous optimum turns, for each tie-break among equally short paths.

For every instance of ``--maps`` generated maps (144 each): the exact optimum's interior
turning points T (convex obstacle corners) and the label path's interior vertices V (cell
centres, the paper's rule). Printed per tie-break and tolerance (``labels.tie_break``,
``labels.tie_tolerance``): the median and 90th percentile distance from each T to the
nearest V, the share of T with a V within 3 px (recall: where a shortcut really bends, found
by the label), the median distance from each V to the nearest T and the share of V with a T
within 3 px (precision: label vertices where the optimum turns), their F1, interior vertices
per path, and the labelling rate (instances/s on one core; ``exact`` computes the optimum
first). The default of ``conf/labels`` is the row of highest F1.

    python benchmarks/bench_tie_break.py [--maps 40]
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from vnrrt.data.label import label_map
from vnrrt.grid import MOVES
from vnrrt.maps.config import DataConfig
from vnrrt.maps.generate import generate_map, map_rng
from vnrrt.search import any_angle_path

OPTIONS = [("turns", 0.0)] + [(tb, t) for tb in ("line", "exact") for t in (0, 2, 3, 5, 8, 12)]


def nearest(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """For each point of ``a`` (N, 2), the distance to the nearest point of ``b`` (M, 2)."""
    if len(a) == 0 or len(b) == 0:
        return np.full(len(a), np.inf)
    return np.sqrt(((a[:, None, :] - b[None, :, :]) ** 2).sum(-1)).min(1)


def measure(maps: list, tie_break: str, tolerance: float) -> dict:
    t_to_v, v_to_t, counts, seconds, n = [], [], [], 0.0, 0
    for fm in maps:
        tick = time.perf_counter()
        lab = label_map(fm, (1, 2, 3), tie_break, tolerance)
        seconds += time.perf_counter() - tick
        offs = np.r_[0, np.cumsum(lab.n_moves)]
        voffs = np.r_[0, np.cumsum(lab.n_vertices)]
        for i, (si, gi) in enumerate(zip(lab.start_index, lab.goal_index, strict=True)):
            s, g = fm.starts[si], fm.goals[gi]
            steps = MOVES[lab.moves[offs[i] : offs[i + 1]].astype(np.int64)]
            path = np.vstack([s, s + np.cumsum(steps, axis=0)])
            verts = path[lab.vertex_steps[voffs[i] : voffs[i + 1]].astype(np.int64)][1:-1] + 0.5
            turns = any_angle_path(fm.grid, s + 0.5, g + 0.5)[0][1:-1]
            t_to_v += list(nearest(turns, verts))
            v_to_t += list(nearest(verts, turns))
            counts.append(len(verts))
            n += 1
    t, v = np.array(t_to_v), np.array(v_to_t)
    t, v = t[np.isfinite(t)], v[np.isfinite(v)]
    recall, precision = np.mean(t <= 3.0), np.mean(v <= 3.0)
    return {"T->V median": np.median(t), "T->V p90": np.percentile(t, 90),
            "recall@3px": recall, "V->T median": np.median(v), "precision@3px": precision,
            "F1": 2 * recall * precision / max(recall + precision, 1e-12),
            "V per path": np.mean(counts), "instances/s": n / seconds}  # fmt: skip


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--maps", type=int, default=40)
    args = ap.parse_args(argv)
    maps = [generate_map(map_rng(11, i), DataConfig()) for i in range(args.maps)]
    label_map(maps[0], (1, 2, 3), "exact")  # compile
    rows = {(tb, tol): measure(maps, tb, tol) for tb, tol in OPTIONS}
    keys = list(next(iter(rows.values())))
    print(f"{'tie-break':<10}{'tolerance':>10}" + "".join(f"{k:>15}" for k in keys))
    for (tb, tol), row in rows.items():
        print(f"{tb:<10}{tol:>10g}" + "".join(f"{row[k]:>15.3g}" for k in keys))
    (tb, tol), best = max(rows.items(), key=lambda kv: kv[1]["F1"])
    print(f"highest F1: tie_break={tb} tie_tolerance={tol:g} (F1 {best['F1']:.3f})")


if __name__ == "__main__":
    main()
