"""Oracle heatmaps, the quality mix, the study's configurations and the regime cells: each
oracle's support lies where its definition says, mixing degrades towards uniform, sweep
cells change the setting they name (checked through planner results), and a perfect path
heatmap makes NRRT* reach the A*-relative optimum in far fewer iterations than RRT*."""

import numpy as np
import pytest
from scipy import ndimage

from vnrrt.data.instances import EvalInstance
from vnrrt.evaluation.config import Configurations, OracleConfig, RegimeConfig
from vnrrt.evaluation.keys import ConfigKey
from vnrrt.evaluation.sampling_ideas.design import oracle_keys, regime_cells
from vnrrt.evaluation.sources import (
    ORACLE_KINDS,
    instance_heatmap,
    mass_near,
    mix,
    oracle_heatmap,
    target_mask,
)
from vnrrt.evaluation.trials import run_trials
from vnrrt.maps.config import DataConfig
from vnrrt.maps.generate import generate_map, map_rng
from vnrrt.planners import PlannerConfig, plan
from vnrrt.search import any_angle_path, astar, path_vertices


def make_instance(map_id: int, k: int = 0) -> EvalInstance:
    """Instance k of a generated 200x200 map (start k, goal k), labelled like the pipeline."""
    fm = generate_map(map_rng(0, map_id), DataConfig())
    s, g = tuple(int(v) for v in fm.starts[k]), tuple(int(v) for v in fm.goals[k])
    path, length = astar(fm.grid, s, g)
    exact_path, exact = any_angle_path(fm.grid, np.add(s, 0.5), np.add(g, 0.5))
    return EvalInstance(
        map_id,
        (0, map_id),
        "random",
        f"map{map_id}",
        map_id,
        fm.grid,
        s,
        g,
        length,
        exact,
        exact,
        path,
        path_vertices(path),
        exact_path,
    )


@pytest.fixture(scope="module")
def turning() -> EvalInstance:
    """A generated instance whose A* path has interior vertices and a turning exact path."""
    for map_id in range(40):
        inst = make_instance(map_id)
        if len(inst.vertices) >= 4 and len(inst.exact_path) >= 3:
            return inst
    raise AssertionError("no instance with turns in 40 maps")


@pytest.mark.parametrize("kind", ORACLE_KINDS)
def test_oracles_are_probability_maps_with_maximum_one(turning, kind):
    a = oracle_heatmap(kind, turning.grid, turning.start_cell, turning.goal_cell, sigma=1.0)
    b = oracle_heatmap(kind, turning.grid, turning.start_cell, turning.goal_cell, sigma=1.0)
    assert a.shape == turning.grid.shape and a.dtype == np.float32
    assert a.min() >= 0 and a.max() == pytest.approx(1.0)
    assert np.array_equal(a, b)  # deterministic
    assert not a[turning.grid != 0].any()  # nothing on obstacles
    np.testing.assert_allclose(instance_heatmap(kind, turning), a, atol=1e-6)  # from labels


def near(points: np.ndarray, shape, radius: float) -> np.ndarray:
    """(H, W) bool: pixel centres within ``radius`` of any of ``points`` (K, 2) (x, y)."""
    ys, xs = np.mgrid[: shape[0], : shape[1]] + 0.5
    d = np.full(shape, np.inf)
    for x, y in np.asarray(points, float).reshape(-1, 2):
        d = np.minimum(d, np.hypot(xs - x, ys - y))
    return d <= radius


@pytest.mark.parametrize("sigma", [1.0, 2.0])
def test_each_oracle_puts_its_weight_where_its_definition_says(turning, sigma):
    g, s, e = turning.grid, turning.start_cell, turning.goal_cell
    interior = turning.vertices[1:-1] + 0.5
    hot = oracle_heatmap("oracle_vertex", g, s, e, sigma) > 0.5
    assert hot.any() and not (hot & ~near(interior, g.shape, 3 * sigma)).any()
    ends = oracle_heatmap("oracle_endpoints", g, s, e, sigma) > 0.5
    _, count = ndimage.label(ends)
    assert count == 2  # exactly two peaks: start and goal
    assert ends[s[1], s[0]] and ends[e[1], e[0]]
    taut = oracle_heatmap("oracle_taut_vertex", g, s, e, sigma) > 0.5
    assert not (taut & ~near(turning.exact_path[1:-1], g.shape, 3 * sigma + 1)).any()
    path = oracle_heatmap("oracle_path", g, s, e, sigma)
    assert mass_near(path, target_mask(turning, "path"), 3.0) > (0.95 if sigma == 1 else 0.85)
    with_ends = oracle_heatmap("oracle_vertex_endpoints", g, s, e, sigma) > 0.5
    assert with_ends[s[1], s[0]] and not hot[s[1], s[0]]  # endpoints in one, not the other


def test_mixing_goes_from_the_oracle_to_uniform(turning):
    heat = instance_heatmap("oracle_vertex", turning)
    free = turning.grid == 0
    uniform = mix(heat, turning.grid, 0.0)
    assert np.allclose(uniform[free], 1.0) and not uniform[~free].any()
    np.testing.assert_allclose(mix(heat, turning.grid, 1.0), heat, atol=1e-6)
    mask = target_mask(turning, "interior_vertices")
    masses = [mass_near(mix(heat, turning.grid, q), mask, 3.0) for q in (1.0, 0.5, 0.1, 0.0)]
    assert masses == sorted(masses, reverse=True) and masses[-1] < 0.05 < 0.9 < masses[0]
    with pytest.raises(ValueError, match="q must be in"):
        mix(heat, turning.grid, 1.5)


def test_the_study_has_every_idea_and_parses_its_keys():
    nets = {"nrrt_star": "nrrtnet", "vnrrt_star": "vertexnet", "m_vnrrt_star": "vertexnet"}
    ev = Configurations(sources=nets, informed=True)
    oc = OracleConfig(qualities=[1.0, 0.1])
    keys = [k.text for k in oracle_keys(oc, ev, [0.5, 0.9], 0.5)]
    assert len(keys) == len(set(keys))
    for key in (
        "rrt_star",
        "nrrt_star",
        "m_vnrrt_star@0.9",
        "nrrt_star[oracle_path]",
        "vnrrt_star[oracle_vertex]",
        "m_vnrrt_star@0.5[oracle_taut_vertex]",
        "vnrrt_star[oracle_vertex@q0.1]",
        "nrrt_star[oracle_path@q0.1]",
    ):
        assert key in keys, key
    assert "rrt_star+informed" in keys and "nrrt_star+informed" in keys
    assert ConfigKey.parse("m_vnrrt_star@0.5[oracle_vertex]") == ConfigKey(
        "m_vnrrt_star", 0.5, "oracle_vertex", named_source=True
    )
    assert ConfigKey.parse("vnrrt_star", {"vnrrt_star": "vertexnet"}).source == "vertexnet"


def test_the_oracle_study_runs_the_configured_planners_and_informed_flag():
    """``eval.planners`` and ``eval.informed`` decide the study's network configurations
    (no default stands in for them)."""
    nets = {"nrrt_star": "nrrtnet", "vnrrt_star": "vertexnet", "m_vnrrt_star": "vertexnet"}
    ev = Configurations(planners=["rrt_star", "vnrrt_star"], sources=nets, informed=False)
    oc = OracleConfig(kinds=["oracle_path"], qualities=[1.0])
    keys = [k.text for k in oracle_keys(oc, ev, [0.5], 0.5)]
    assert keys == ["rrt_star", "vnrrt_star", "nrrt_star[oracle_path]"]


def test_a_sweep_cell_changes_the_setting_it_names(turning):
    """Checked through planner results: every tree edge is at most the Steer step (shrinking
    radius, which never exceeds it) or the fixed near radius (a parent chosen among the near
    nodes), the fixed radius 2 x eta does give longer edges, and a goal radius of 2 px bounds
    the final segment into the goal."""
    modes = ["shrinking", "fixed2"]
    rc = RegimeConfig(etas=[5.0, 20.0], radius_modes=modes, goal_radii=[None, 2.0])
    cells = regime_cells(rc)
    assert len(cells) == 8 and cells["eta=5 radius=fixed2 goal=2"]["fixed_radius"] == 10.0
    base, longest = PlannerConfig(), {}
    for label, over in cells.items():
        r = plan(
            turning.grid,
            turning.start,
            turning.goal,
            config=base.replace(**over),
            keep_tree=True,
            seed=1,
            stop="initial",
        )
        pts, par = r.tree_points, r.tree_parents
        child = np.flatnonzero(par >= 0)[:-1]  # the goal (last node) joins by its own rule
        edges = np.hypot(*(pts[child] - pts[par[child]]).T)
        limit = over["eta"] if over["radius_mode"] == "shrinking" else over["fixed_radius"]
        assert edges.max() <= limit + 1e-6, label
        longest[label] = edges.max()
        last = np.hypot(*(r.path[-1] - r.path[-2]))
        goal_limit = over["eta"] if over["goal_radius"] is None else over["goal_radius"]
        assert last <= goal_limit + 1e-6, label
    assert longest["eta=5 radius=fixed2 goal=eta"] > 5.5  # parents beyond the Steer step
    assert longest["eta=20 radius=shrinking goal=eta"] > 10.0  # a longer step is used


def test_a_perfect_path_heatmap_makes_nrrt_reach_the_optimum_in_far_fewer_iterations():
    """Fails if the oracle or its plumbing (source -> heatmap -> sampler) is wrong."""
    instances = [make_instance(m, k) for m in range(3) for k in range(2)]
    keys = [ConfigKey("rrt_star"), ConfigKey("nrrt_star", None, "oracle_path")]
    table = run_trials(instances, keys, {("random", "optimal"): 3}, workers=1)
    assert table["success"].all()
    med = table.groupby("key")["iterations"].median()
    assert med["nrrt_star"] < 0.5 * med["rrt_star"], med.to_dict()
    assert table.loc[table["key"] == "nrrt_star", "heat_mass"].min() > 0.9


def test_taut_oracles_are_measured_against_the_exact_path(turning):
    heat = instance_heatmap("oracle_taut_vertex", turning)
    assert mass_near(heat, target_mask(turning, "taut_vertices"), 3.0) > 0.9
    heat = instance_heatmap("oracle_taut_path", turning)
    assert mass_near(heat, target_mask(turning, "taut_path"), 3.0) > 0.9
