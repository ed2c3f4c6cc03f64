"""Turning points and free cells of a results bundle's instances, rebuilt where the bundle
predates them.

A bundle exported before the strata (``instances.json`` without ``turns``) still names each
instance: a named map by its map set, a random instance as ``map<id>/inst<i>`` (global map
id, instance index in its shard; instances are goal-major over the map's starts and goals,
:func:`vnrrt.data.label.label_map`). The maps are regenerated from the bundle's parameters
(:func:`vnrrt.maps.generate.generate_map`, seeded by ``(seed, map id)`` only), the exact
optimum recomputed (:func:`vnrrt.search.any_angle_path`), and each length checked against
the bundle's own reference of stop ``optimal_any_angle`` (the exact optimum the trials used):
a map rebuilt wrong is refused, never used.

``python -m vnrrt.pipeline.bundle_turns --bundle reports/cpu/results`` adds ``turns`` and
``free_cells`` (each instance's map, the RRT* gamma's area) to the bundle's
``instances.json``.
"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

import numpy as np


def _problem(row, data, size: int, seed: int, per_shard: int):
    """``(grid, start, goal)`` of one trial-table instance row (module doc)."""
    from vnrrt.maps.generate import generate_map, map_rng
    from vnrrt.maps.named import NAMES, named_map

    if row["map_set"] != "random":
        fm, k = named_map(NAMES[int(row["map_set"].split("_")[1]) - 1], size), 0
    else:
        map_part, inst_part = row["map"].split("/")
        map_id, index = int(map_part[3:]), int(inst_part[4:])
        fm = generate_map(map_rng(seed, map_id), data)
        k = index - (map_id % per_shard) * len(fm.starts) * len(fm.goals)
    goal, start = divmod(k, len(fm.starts))
    return fm.grid, tuple(fm.starts[start] + 0.5), tuple(fm.goals[goal] + 0.5)


def bundle_turns(bundle: Path) -> tuple[dict[int, int], dict[int, int]]:
    """``({instance: turning points}, {instance: free cells})`` of every instance of the
    bundle's paper comparison, each exact length checked against the bundle's (module doc);
    ValueError on a mismatch."""
    import pandas as pd

    from vnrrt.config import load_params, section
    from vnrrt.maps.config import DataConfig
    from vnrrt.search import any_angle_path

    cfg = load_params(bundle / "params.yaml")
    data = section(cfg, "data", DataConfig)
    table = pd.read_csv(bundle / "trials.csv.gz")
    rows = table[table["stop"] == "optimal_any_angle"].groupby("instance").first()
    if rows.empty:
        raise ValueError(f"{bundle}: no optimal_any_angle trials to check rebuilt maps against")
    out, free = {}, {}
    for inst, row in rows.iterrows():
        grid, start, goal = _problem(row, data, int(cfg.data.size), int(cfg.seed),
                                     int(cfg.scale.maps_per_shard))  # fmt: skip
        points, length = any_angle_path(grid, start, goal)
        if not math.isclose(length, row["reference_length"], rel_tol=1e-9):
            want = row["reference_length"]
            raise ValueError(f"{bundle}: instance {inst} ({row['map']}) rebuilt with exact "
                             f"length {length}, the bundle's {want}")  # fmt: skip
        out[int(inst)] = len(np.asarray(points)) - 2
        free[int(inst)] = int(np.count_nonzero(np.asarray(grid) == 0))
    return out, free


def main(argv: list[str] | None = None) -> int:
    """The command line (module doc); returns the exit status."""
    from vnrrt.infra.io import read_json, write_json

    parser = argparse.ArgumentParser(prog="python -m vnrrt.pipeline.bundle_turns",
                                     description=__doc__.split("\n\n")[0])  # fmt: skip
    parser.add_argument("--bundle", type=Path, required=True)
    args = parser.parse_args(argv)
    try:
        turns, free = bundle_turns(args.bundle)
    except (OSError, ValueError) as err:
        print(f"vnrrt.pipeline.bundle_turns: error: {err}".splitlines()[0], file=sys.stderr)
        return 2
    path = args.bundle / "instances.json"
    add = {"turns": {str(i): turns[i] for i in sorted(turns)},
           "free_cells": {str(i): free[i] for i in sorted(free)}}  # fmt: skip
    write_json(path, read_json(path) | add)
    print(path)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
