"""What the benchmark-maps study runs (settings: ``conf/bench_maps``, the section ``bench_maps``).

* **Scenarios.** Per map of ``bench_maps.maps`` (its ``<map>.map`` and ``<map>.map.scen`` in
  ``paths.movingai``), ``bench_maps.per_bucket`` queries of each listed length bucket, drawn
  without replacement by a generator seeded with (``seed``, map name, bucket)
  (:func:`sample_bucket`): the same draw on every run, independent of the other buckets and
  maps. Queries with an endpoint on an obstacle (older files) are never drawn.
* **Instances.** Each drawn query becomes an
  :class:`~vnrrt.data.instances.EvalInstance` (:func:`build_instance`): start and goal at its
  cells' centres, the A* label (``labels.tie_break``) with its vertices (the oracles' targets),
  the exact any-angle optimum (the stop rule's reference); ``map_set`` is the map's name,
  ``cluster`` the query's bucket.
* **Configurations** (:func:`configurations`): RRT*, NRRT*, VNRRT* and M-VNRRT* at
  ``planner.tau`` sampling their networks of ``eval.sources``, and the envelopes of the
  oracle families in ``bench_maps.ideas`` (the sampling-ideas study's choice on random maps
  for the exact-optimum stop rule), every one ``bench_maps.trials`` paired trials per
  instance, stopping within ``planner.eps`` of the exact optimum (``optimal_any_angle``).
"""

from __future__ import annotations

import math
import zlib
from pathlib import Path

import numpy as np

from vnrrt.config import ConfigError
from vnrrt.data.instances import EvalInstance
from vnrrt.evaluation.keys import ConfigKey
from vnrrt.evaluation.protocol import TrialJob, trial_jobs
from vnrrt.maps.movingai import (
    Scenario,
    blocked_endpoint,
    check_scenarios,
    read_map,
    read_scen,
)
from vnrrt.search import any_angle_path, astar, path_vertices
from vnrrt.studies.benchmark_maps.config import map_files

STOP = "optimal_any_angle"  # within planner.eps of the exact continuous optimum
KIND = "random"  # the protocol's instance kind whose trial counts the jobs use
NETWORK_IDEA = {"nrrt_star": "path", "vnrrt_star": "vertex", "m_vnrrt_star": "vertex"}


def bucket_seed(seed: int, map_name: str, bucket: int) -> np.random.Generator:
    """The generator of one (map, bucket) draw: from the global ``seed``, the map's name and
    the bucket, so that adding a map or a bucket leaves every other draw as it was."""
    return np.random.default_rng([seed, zlib.crc32(map_name.encode()), bucket, 0xBE4C])


def sample_bucket(
    scenarios: list[Scenario], grid: np.ndarray, map_name: str, bucket: int, count: int, seed: int
) -> list[Scenario]:
    """``count`` queries of ``bucket`` drawn without replacement (:func:`bucket_seed`), in
    file order; queries with an endpoint on an obstacle of ``grid`` ``(H, W)`` are never
    drawn. :class:`ConfigError` naming map and bucket when it holds fewer than ``count``."""
    pool = [s for s in scenarios if s.bucket == bucket and blocked_endpoint(grid, s) is None]
    if len(pool) < count:
        raise ConfigError(
            f"invalid config value bench_maps.maps.{map_name}: bucket {bucket} "
            f"holds {len(pool)} plannable queries, fewer than "
            f"bench_maps.per_bucket={count}"
        )
    chosen = bucket_seed(seed, map_name, bucket).choice(len(pool), count, replace=False)
    return [pool[i] for i in sorted(int(c) for c in chosen)]


def sample_scenarios(
    scenarios: list[Scenario],
    grid: np.ndarray,
    map_name: str,
    buckets: list[int],
    count: int,
    seed: int,
) -> list[Scenario]:
    """The queries of every bucket of ``buckets`` (:func:`sample_bucket`), bucket by bucket."""
    return [s for b in buckets for s in sample_bucket(scenarios, grid, map_name, b, count, seed)]


def build_instance(
    index: int, map_id: int, map_name: str, grid: np.ndarray, query: Scenario, tie_break: str
) -> EvalInstance:
    """Query ``query`` on ``grid`` ``(H, W)`` (1 = obstacle) as instance ``index`` of the
    study: key ``(map_id, file line)``, ``map_set`` the map's name, ``cluster`` the bucket,
    the A* label (``tie_break``) and the exact optimum between the cells' centres (px). The
    taut A* length, which nothing here reads, is NaN."""
    path, length = astar(grid, query.start, query.goal, tie_break)
    exact_path, exact = any_angle_path(grid, query.start_point, query.goal_point)
    return EvalInstance(
        index=index,
        key=(map_id, query.line),
        map_set=map_name,
        map=f"{map_name}:{query.line}",
        cluster=query.bucket,
        grid=np.asarray(grid, np.uint8),
        start_cell=tuple(query.start),
        goal_cell=tuple(query.goal),
        astar_length=float(length),
        exact_length=float(exact),
        taut_length=math.nan,
        path=path,
        vertices=path_vertices(path),
        exact_path=np.asarray(exact_path, np.float64),
    )


def configurations(
    sources: dict[str, str], tau: float, envelopes: dict[str, str]
) -> list[ConfigKey]:
    """RRT*, NRRT*, VNRRT* and M-VNRRT* at ``tau`` on their networks (``sources``:
    ``eval.sources``), then each envelope of ``envelopes`` (idea -> configuration text)."""
    keys = [ConfigKey("rrt_star")]
    keys += [ConfigKey(p, None, sources[p]) for p in ("nrrt_star", "vnrrt_star")]
    keys.append(ConfigKey("m_vnrrt_star", float(tau), sources["m_vnrrt_star"]))
    return keys + [ConfigKey.parse(envelopes[idea]) for idea in envelopes]


def envelope_keys(selection: dict, ideas: list[str]) -> dict[str, str]:
    """``{idea: configuration text}``: the envelopes the sampling-ideas study chose for the
    exact-optimum stop rule (``selection``: its summary's ``selection`` entry), for ``ideas``;
    :class:`ConfigError` naming an idea it chose none for."""
    chosen = selection.get("envelopes", {}).get(STOP, {})
    missing = [i for i in ideas if i not in chosen]
    if missing:
        raise ConfigError(
            f"the sampling-ideas summary chose no {STOP} envelope for "
            f"{missing} (bench_maps.ideas; re-run stage ideas)"
        )
    return {i: str(chosen[i]) for i in ideas}


def jobs(n_instances: int, keys: list[ConfigKey], trials: int) -> list[TrialJob]:
    """Every trial job, in the protocol's canonical order (instance, configuration, trial)."""
    return trial_jobs([KIND] * n_instances, keys, {(KIND, STOP): trials})


def read_benchmark(folder: str | Path, name: str) -> tuple[np.ndarray, list[Scenario]]:
    """Map ``name``'s grid ``(H, W)`` uint8 (1 = obstacle) and its scenarios, checked to be
    made for its size (:class:`MovingAIError` naming the file and line otherwise)."""
    map_file, scen_file = map_files(folder, name)
    grid = read_map(map_file)
    scenarios = read_scen(scen_file)
    check_scenarios(grid, scenarios, str(scen_file))
    return grid, scenarios
