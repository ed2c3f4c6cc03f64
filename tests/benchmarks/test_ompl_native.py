"""The benchmark's native OMPL harness (benchmarks/ompl_native): it builds against the system's
libompl-dev and reports, on one map, a path whose length is within 1% of our exact optimum
and that it stopped there (its cost threshold). Skipped where libompl-dev is absent."""

import math
import shutil

import numpy as np
import pytest

from benchmarks import ompl_native
from vnrrt.maps.named import named_map
from vnrrt.planners import any_angle_path, polyline_length


@pytest.fixture(scope="module")
def binary():
    try:
        return ompl_native.build()
    except ompl_native.HarnessError as err:
        pytest.skip(f"native OMPL harness not buildable here ({err}); {ompl_native.INSTALL}")


@pytest.mark.parametrize("planner", ["BITstar", "InformedRRTstar"])
def test_the_harness_stops_within_one_percent_of_the_exact_optimum(binary, planner):
    fm = named_map("open", 200)
    s, e = tuple(fm.starts[0] + 0.5), tuple(fm.goals[0] + 0.5)
    exact = any_angle_path(fm.grid, s, e)[1]
    with ompl_native.Harness(binary, seed=3) as native:
        native.set_map(fm.grid)
        r = native.solve(planner, s, e, bound=1.01 * exact, limit=10.0)
    assert 0 < r.first <= r.stop < 10.0 and r.setup > 0
    np.testing.assert_allclose(r.path[[0, -1]], [s, e])
    assert r.cost == pytest.approx(polyline_length(r.path), rel=1e-9)
    # within 1% of our exact reference (OMPL checks states every 0.5 px, so it may cut a
    # corner by a hair and come in below the exact optimum)
    assert abs(r.cost / exact - 1) <= 0.01


def test_rrt_connect_stops_at_its_first_solution(binary):
    """RRT-Connect (no optimizer) answers with its first path: a path round the wall from
    start to goal, its length reported, at least the exact optimum less OMPL's 0.5 px hair;
    with an unreachable bound its first solution still ends the run, well before the limit."""
    grid = np.zeros((60, 60), np.uint8)
    grid[10:50, 30] = 1
    s, e = (10.5, 30.5), (50.5, 30.5)
    exact = any_angle_path(grid, s, e)[1]
    with ompl_native.Harness(binary, seed=3) as native:
        native.set_map(grid)
        r = native.solve(ompl_native.RRT_CONNECT, s, e, bound=0.5 * exact, limit=10.0)
    assert 0 < r.first < 10.0 and math.isnan(r.stop)
    np.testing.assert_allclose(r.path[[0, -1]], [s, e])
    assert r.cost == pytest.approx(polyline_length(r.path), rel=1e-9) and r.cost > 0.99 * exact


def test_a_query_before_any_map_is_an_error(binary):
    with (
        ompl_native.Harness(binary) as native,
        pytest.raises(ompl_native.HarnessError, match="no map"),
    ):
        native.solve("BITstar", (1.5, 1.5), (5.5, 5.5), bound=10.0, limit=1.0)


def test_without_a_compiler_the_build_says_how_to_install(monkeypatch, tmp_path):
    monkeypatch.setattr(shutil, "which", lambda name: None)
    with pytest.raises(ompl_native.HarnessError, match="apt-get install -y libompl-dev g\\+\\+"):
        ompl_native.build(tmp_path)
    assert not any(tmp_path.iterdir())


def test_an_unknown_planner_is_refused(binary):
    with ompl_native.Harness(binary) as native:
        native.set_map(np.zeros((10, 10), np.uint8))
        with pytest.raises(ompl_native.HarnessError, match="unknown planner"):
            native.solve("PRMstar", (1.5, 1.5), (8.5, 8.5), bound=math.inf, limit=0.1)


def test_a_flush_is_answered_and_leaves_the_next_solve_as_it_was(binary):
    """``flush`` (the benchmark's --flush) answers, refuses a negative size, and the solve
    after it, with the harness's RNG seeded alike, gives the same path as without it."""
    g = np.zeros((20, 20), np.uint8)
    g[5:15, 10] = 1
    paths = []
    for flush in (0, 1 << 20):
        with ompl_native.Harness(binary, seed=5) as native:
            native.set_map(g)
            native.flush(flush)
            paths.append(native.solve("BITstar", (2.5, 10.5), (17.5, 10.5), bound=30.0,
                                      limit=1.0).path)  # fmt: skip
            with pytest.raises(ompl_native.HarnessError, match="flush expects BYTES"):
                native.flush(-1)
            after = native.solve("BITstar", (2.5, 10.5), (17.5, 10.5), bound=30.0, limit=1.0)
            assert len(after.path) >= 3  # the harness still answers each command in turn
    assert len(paths[0]) >= 3  # around the wall
    np.testing.assert_array_equal(paths[0], paths[1])


def test_a_bad_map_is_refused_and_the_harness_stays_in_step(binary):
    with ompl_native.Harness(binary) as native:
        with pytest.raises(ompl_native.HarnessError, match="map expects H W and H\\*W cells"):
            native.set_map(np.zeros((0, 5), np.uint8))  # no cells
        native.set_map(np.zeros((10, 10), np.uint8))
        r = native.solve("BITstar", (1.5, 1.5), (8.5, 8.5), bound=12.0, limit=1.0)
    assert len(r.path) >= 2
