"""The benchmark-maps study's design: queries drawn per bucket, seeded and deterministic, each
bucket's draw independent of the others; instances whose references are the published A*
length and the exact optimum; clear errors for a missing or malformed map file and for a
bucket too small; the settings' checks."""

from __future__ import annotations

import numpy as np
import pytest

from tests.conftest import REPO
from vnrrt.config import ConfigError
from vnrrt.maps.movingai import MovingAIError, Scenario
from vnrrt.search import any_angle_length
from vnrrt.studies.benchmark_maps.config import BenchMapsConfig
from vnrrt.studies.benchmark_maps.design import (
    build_instance,
    configurations,
    envelope_keys,
    jobs,
    read_benchmark,
    sample_bucket,
    sample_scenarios,
)

MOVINGAI = REPO / "data" / "movingai"


@pytest.fixture(scope="module")
def lak():
    return read_benchmark(MOVINGAI, "lak304d")


def test_a_bucket_draw_is_seeded_deterministic_and_of_that_bucket(lak):
    grid, scen = lak
    first = sample_bucket(scen, grid, "lak304d", 30, 4, seed=0)
    assert first == sample_bucket(scen, grid, "lak304d", 30, 4, seed=0)
    assert len(set(first)) == 4 and all(s.bucket == 30 for s in first)
    assert [s.line for s in first] == sorted(s.line for s in first)  # file order
    others = {
        tuple(s.line for s in sample_bucket(scen, grid, "lak304d", 30, 4, seed=k))
        for k in range(1, 6)
    }
    assert len(others | {tuple(s.line for s in first)}) > 1  # the seed decides the draw
    pool = [s for s in scen if s.bucket == 30]
    assert set(first) <= set(pool)


def test_each_bucket_is_drawn_independently_of_the_others(lak):
    grid, scen = lak
    both = sample_scenarios(scen, grid, "lak304d", [10, 30], 3, seed=7)
    assert both[:3] == sample_bucket(scen, grid, "lak304d", 10, 3, seed=7)
    assert both[3:] == sample_bucket(scen, grid, "lak304d", 30, 3, seed=7)
    assert sample_scenarios(scen, grid, "lak304d", [30], 3, seed=7) == both[3:]


def test_a_query_with_a_blocked_endpoint_is_never_drawn():
    grid = np.zeros((8, 8), np.uint8)
    grid[0, 0] = 1
    blocked = Scenario(0, "m.map", 8, 8, (0, 0), (7, 7), 9.9, line=2)
    free = [Scenario(0, "m.map", 8, 8, (1, k), (7, 7), 9.0, line=3 + k) for k in range(3)]
    for seed in range(20):
        got = sample_bucket([blocked, *free], grid, "m", 0, 3, seed)
        assert blocked not in got and sorted(got, key=lambda s: s.line) == free


def test_a_bucket_with_too_few_queries_names_map_and_bucket(lak):
    grid, scen = lak
    with pytest.raises(ConfigError, match=r"bench_maps\.maps\.lak304d: bucket 999 holds 0"):
        sample_bucket(scen, grid, "lak304d", 999, 1, seed=0)


def test_an_instance_keeps_the_published_astar_length_and_the_exact_optimum(lak):
    grid, scen = lak
    for i, q in enumerate(sample_scenarios(scen, grid, "lak304d", [5, 40], 2, seed=0)):
        inst = build_instance(i, 3, "lak304d", grid, q, "line")
        assert inst.astar_length == pytest.approx(q.optimal, rel=5e-6)  # 6 significant digits
        exact = any_angle_length(grid, q.start_point, q.goal_point)
        assert inst.exact_length == pytest.approx(exact, rel=1e-12)
        assert inst.reference("optimal_any_angle") == inst.exact_length
        assert (inst.map_set, inst.cluster, inst.key) == ("lak304d", q.bucket, (3, q.line))
        assert tuple(inst.path[0]) == q.start and tuple(inst.path[-1]) == q.goal
        assert inst.grid.shape == (194, 193) and inst.start == q.start_point


def test_a_missing_or_malformed_map_file_is_named(tmp_path):
    with pytest.raises(MovingAIError, match=r"nomap\.map: no such file"):
        read_benchmark(tmp_path, "nomap")
    (tmp_path / "bad.map").write_text("type octile\nheight 2\nwidth 2\nmap\n..\n.x\n")
    (tmp_path / "bad.map.scen").write_text("version 1\n")
    with pytest.raises(MovingAIError, match=r"bad\.map, line 6: unknown terrain 'x'"):
        read_benchmark(tmp_path, "bad")
    (tmp_path / "bad.map").write_text("type octile\nheight 2\nwidth 2\nmap\n..\n..\n")
    (tmp_path / "bad.map.scen").write_text("version 1\n0\tbad.map\t3\t2\t0\t0\t1\t1\t1.41421\n")
    with pytest.raises(MovingAIError, match=r"bad\.map\.scen, line 2: scenario for a 3x2 map"):
        read_benchmark(tmp_path, "bad")


def test_the_configurations_and_jobs_cover_every_trial():
    sources = {"nrrt_star": "nrrtnet", "vnrrt_star": "vertexnet", "m_vnrrt_star": "vertexnet"}
    env = {"path": "nrrt_star~0.5[oracle_path@s1]", "vertex": "vnrrt_star~0.5[oracle_vertex@s4]"}
    keys = [k.text for k in configurations(sources, 0.7, env)]
    assert keys == ["rrt_star", "nrrt_star", "vnrrt_star", "m_vnrrt_star@0.7", *env.values()]
    todo = jobs(3, configurations(sources, 0.7, env), 2)
    assert sum(j.count for j in todo) == 3 * 6 * 2
    assert {j.stop for j in todo} == {"optimal_any_angle"}
    selection = {"envelopes": {"optimal_any_angle": env, "optimal": {}}}
    assert envelope_keys(selection, ["vertex"]) == {"vertex": env["vertex"]}
    with pytest.raises(ConfigError, match="no optimal_any_angle envelope for"):
        envelope_keys({"envelopes": {"optimal": env}}, ["path"])


@pytest.mark.parametrize(
    ("field", "value", "message"),
    [
        ("maps", {"arena": []}, "bench_maps.maps.arena"),
        ("trials", 1, "bench_maps.trials"),
        ("ideas", ["control"], "bench_maps.ideas"),
        ("report", [], "bench_maps.report"),
    ],
)
def test_the_settings_refuse_what_cannot_run(field, value, message):
    good = {
        "maps": {"arena": [3]},
        "per_bucket": 1,
        "trials": 2,
        "ideas": ["path"],
        "report": ["benchmark_maps"],
    }
    BenchMapsConfig(**good).validate()
    with pytest.raises(ConfigError, match=message):
        BenchMapsConfig(**(good | {field: value})).validate()
