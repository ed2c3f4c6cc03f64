"""Oracle heatmaps, the quality mix, the blend, the obstacle rule, the study's design and the
regime cells: each oracle's support lies where its definition says, blur and mixing move the
mass near the target as designed, the blend spans the two ideas with equal mass per part,
every heatmap source obeys the obstacle rule, selection and evaluation share no base map,
sweep cells change the setting they name (checked through planner results), and a perfect
path heatmap makes NRRT* reach the A*-relative optimum in far fewer iterations than RRT*."""

import math

import numpy as np
import pytest
from scipy import ndimage

from vnrrt.config import ConfigError
from vnrrt.data.instances import EvalInstance
from vnrrt.evaluation.config import Configurations, OracleConfig, RegimeConfig
from vnrrt.evaluation.keys import ConfigKey
from vnrrt.evaluation.oracles import OracleSource, blend, dilute, oracle_heatmap
from vnrrt.evaluation.sources import (
    ORACLE_KINDS,
    allowed_cells,
    instance_heatmap,
    mass_near,
    target_mask,
)
from vnrrt.evaluation.trials import run_trials
from vnrrt.maps.config import DataConfig
from vnrrt.maps.generate import generate_map, map_rng
from vnrrt.planners import PlannerConfig, plan
from vnrrt.search import any_angle_path, astar, path_vertices
from vnrrt.studies.sampling_ideas.design import (
    evaluation_keys,
    family_members,
    idea_of,
    protocol_settings,
    regime_cells,
    selection_keys,
    split_instances,
)

# a protocol with a Steer step of 7 px: no grid cell below repeats it
ELSEWHERE = protocol_settings(PlannerConfig(eta=7.0))


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


def everywhere(inst) -> np.ndarray:
    """The default obstacle rule's cells: every cell."""
    return allowed_cells(inst.grid, False)


@pytest.mark.parametrize("kind", ORACLE_KINDS)
def test_oracles_are_probability_maps_with_maximum_one(turning, kind):
    g, s, e = turning.grid, turning.start_cell, turning.goal_cell
    a = oracle_heatmap(kind, g, s, e, sigma=1.0, zero_obstacles=True)
    b = oracle_heatmap(kind, g, s, e, sigma=1.0, zero_obstacles=True)
    assert a.shape == turning.grid.shape and a.dtype == np.float32
    assert a.min() >= 0 and a.max() == pytest.approx(1.0)
    assert np.array_equal(a, b)  # deterministic
    assert not a[turning.grid != 0].any()  # the free-cells rule: nothing on obstacles
    free = allowed_cells(g, True)
    got = instance_heatmap(f"{kind}@s1", turning, None, 0.0, free)
    np.testing.assert_allclose(got, a, atol=1e-6)  # from the labels, the same
    leaky = oracle_heatmap(kind, g, s, e, sigma=4.0, zero_obstacles=False)
    assert leaky[g != 0].any() or kind == "oracle_endpoints"  # the default rule: blur leaks


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
    free = allowed_cells(turning.grid, True)
    heat = instance_heatmap("oracle_vertex@s1", turning, None, 0.0, free)
    uniform = dilute(heat, free, 0.0)
    assert np.allclose(uniform[free], 1.0) and not uniform[~free].any()
    np.testing.assert_allclose(dilute(heat, free, 1.0), heat, atol=1e-6)
    mask = target_mask(turning, "interior_vertices")
    masses = [mass_near(dilute(heat, free, q), mask, 3.0) for q in (1.0, 0.5, 0.1, 0.0)]
    assert masses == sorted(masses, reverse=True) and masses[-1] < 0.05 < 0.9 < masses[0]
    with pytest.raises(ValueError, match="q must be in"):
        dilute(heat, free, 1.5)


def test_the_blend_spans_the_two_ideas_with_equal_mass_per_part(turning):
    every = everywhere(turning)
    path = instance_heatmap("oracle_path@s2", turning, None, 0.0, every).astype(float)
    vertex = instance_heatmap("oracle_vertex@s2", turning, None, 0.0, every).astype(float)
    unit = lambda h: h / h.sum()  # noqa: E731
    np.testing.assert_allclose(unit(blend(path, vertex, 0.0)), unit(path), atol=1e-7)
    np.testing.assert_allclose(unit(blend(path, vertex, 1.0)), unit(vertex), atol=1e-7)
    half = unit(blend(path, vertex, 0.5).astype(float))
    # equal mass per part: half the mass is the path oracle's, half the vertex oracle's
    np.testing.assert_allclose(half, 0.5 * unit(path) + 0.5 * unit(vertex), atol=1e-7)
    via_source = instance_heatmap("oracle_blend@w0.5@s2", turning, None, 0.0, every)
    np.testing.assert_allclose(unit(via_source.astype(float)), half, atol=1e-6)
    with pytest.raises(ValueError, match="w must be in"):
        blend(path, vertex, 1.5)


@pytest.mark.parametrize("kind", ["oracle_path", "oracle_vertex"])
def test_blur_spreads_the_mass_and_dilution_dilutes_it(turning, kind):
    """A property of the families: more blur, less of the heatmap's mass near its target;
    a lower signal fraction q, less again, down to a uniform map's share at q = 0."""
    every = everywhere(turning)
    mask = target_mask(turning, "path" if kind == "oracle_path" else "interior_vertices")
    by_sigma = [mass_near(instance_heatmap(f"{kind}@s{s:g}", turning, None, 0.0, every), mask, 3.0)
                for s in (1.0, 2.0, 4.0, 8.0, 16.0)]  # fmt: skip
    assert by_sigma == sorted(by_sigma, reverse=True) and by_sigma[0] > 1.5 * by_sigma[-1]
    uniform = mass_near(every.astype(float), mask, 3.0)
    by_q = [mass_near(instance_heatmap(f"{kind}@s2@q{q:g}", turning, None, 0.0, every), mask, 3.0)
            for q in (1.0, 0.5, 0.1, 0.0)]  # fmt: skip
    assert by_q == sorted(by_q, reverse=True) and by_q[-1] == pytest.approx(uniform, rel=1e-5)


def test_oracle_sources_round_trip_and_refuse_bad_text():
    for text in ("oracle_vertex@s4", "oracle_blend@w0.25@s2", "oracle_path@s1@q0.1"):
        assert OracleSource.parse(text).text == text
    with pytest.raises(ValueError, match="the blend, and only the blend"):
        OracleSource.parse("oracle_path@w0.5@s1")
    with pytest.raises(ValueError, match="expected kind"):
        OracleSource.parse("oracle_path@x1")


def test_the_families_hold_every_target_blur_and_mix():
    oc = OracleConfig(sigmas=[1.0, 4.0], mixes=[0.25, 0.75], blend_weights=[0.0, 1.0])
    members = family_members(oc, tau=0.9)
    ideas = {"path", "vertex", "taut_vertex", "masked_vertex", "control", "blend"}
    assert set(members) == ideas
    assert len(members["vertex"]) == 2 * 2 * 2 and len(members["blend"]) == 2 * 2 * 2
    texts = [k.text for k in selection_keys(oc, tau=0.9)]
    assert texts[0] == "rrt_star" and len(texts) == len(set(texts))
    wanted = (
        "nrrt_star~0.25[oracle_path@s1]",
        "vnrrt_star~0.75[oracle_taut_vertex@s4]",
        "vnrrt_star~0.25[oracle_blend@w1@s4]",
        "vnrrt_star~0.75[oracle_endpoints@s1]",
        "m_vnrrt_star@0.9~0.25[oracle_vertex_endpoints@s4]",  # a perfect M-VNRRT* heatmap
    )
    for text in wanted:
        assert text in texts, text
    for idea, keys in members.items():  # each member is found in its own family again
        assert {idea_of(k, oc) for k in keys} == {idea}, idea


def test_the_default_grids_reach_mix_1_and_bad_families_are_named():
    oc = OracleConfig()
    oc.validate()
    assert max(oc.mixes) == 1.0 and {0.9, 0.95} <= set(oc.mixes)
    assert oc.planner_of("masked_vertex") == "m_vnrrt_star" and oc.planner_of("blend") == (
        "vnrrt_star"
    )
    bad = (
        ({"planners": {"nope": "nrrt_star"}}, "oracle.planners.nope"),
        ({"planners": {"path": "rrt_star"}}, "oracle.planners.path"),
        ({"planners": {"masked_vertex": "vnrrt_star"}}, "is in vertex too"),
        ({"mixes": [0.5, 1.5]}, "oracle.mixes"),
        ({"mixes": [0.0, 0.5]}, "oracle.mixes"),
    )
    for change, message in bad:
        with pytest.raises(ConfigError, match=message):
            OracleConfig(**change).validate()


def test_selection_and_evaluation_share_no_base_map():
    instances, clusters = list(range(40)), [i // 3 for i in range(40)]  # 14 maps
    sel, ev = split_instances(instances, clusters, 0.5, seed=0)
    assert sorted(sel + ev) == instances
    assert not {clusters[i] for i in sel} & {clusters[i] for i in ev}
    assert len({clusters[i] for i in sel}) == 7
    assert split_instances(instances, clusters, 0.5, seed=0) == (sel, ev)
    assert split_instances(instances, clusters, 0.5, seed=1) != (sel, ev)  # seeded


def test_the_evaluation_runs_the_envelopes_and_every_blend_weight():
    nets = {"nrrt_star": "nrrtnet", "vnrrt_star": "vertexnet", "m_vnrrt_star": "vertexnet"}
    ev = Configurations(sources=nets, informed=False)
    oc = OracleConfig(blend_weights=[0.0, 0.5, 1.0], qualities=[1.0, 0.1])
    rc = RegimeConfig(etas=[10.0], radius_modes=["shrinking"], gamma_factors=[1.0],
                      goal_radii=[None], configurations=["rrt_star", "vnrrt_star"])  # fmt: skip
    env = {"optimal": {"path": "nrrt_star~0.5[oracle_path@s2]",
                       "blend": "vnrrt_star~0.5[oracle_blend@w0.5@s4]"}}  # fmt: skip
    cells = evaluation_keys(env, oc, rc, ev, ELSEWHERE)
    assert set(cells) == {"protocol", "eta=10 radius=shrinking goal=eta"}
    grid = {k.text for k in cells["eta=10 radius=shrinking goal=eta"]}
    assert {"rrt_star", "vnrrt_star", *env["optimal"].values()} <= grid
    assert {f"vnrrt_star~0.5[oracle_blend@w{w:g}@s4]" for w in (0, 0.5, 1)} <= grid
    protocol = {k.text for k in cells["protocol"]}
    assert "nrrt_star~0.5[oracle_path@s2@q0.1]" in protocol  # the quality curve
    assert "rrt_star+free" in protocol and "nrrt_star~0.5[oracle_path@s2]+free" in protocol


def test_a_sweep_cell_changes_the_setting_it_names(turning):
    """Checked through planner results: every tree edge is at most the Steer step (shrinking
    radius, which never exceeds it) or the fixed near radius (a parent chosen among the near
    nodes), the fixed radius 2 x eta does give longer edges, and a goal radius of 2 px bounds
    the final segment into the goal."""
    modes = ["shrinking", "fixed2"]
    rc = RegimeConfig(etas=[5.0, 20.0], radius_modes=modes, gamma_factors=[1.0],
                      goal_radii=[None, 2.0])  # fmt: skip
    cells = regime_cells(rc, protocol_settings(PlannerConfig()))
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


def test_an_unlimited_step_and_a_small_gamma_change_the_tree(turning):
    """Through the result: an unlimited Steer step (eta = inf) grows edges longer than 20 px,
    and gamma_factor 0.01 makes the shrinking radius fall below eta (parents closer), an
    unlimited fixed radius is left out of the grid."""
    rc = RegimeConfig(etas=[10.0, math.inf], radius_modes=["shrinking", "fixed1"],
                      gamma_factors=[1.0, 0.01], goal_radii=[None])  # fmt: skip
    cells = regime_cells(rc, ELSEWHERE)
    assert "eta=inf radius=fixed1 goal=eta" not in cells and len(cells) == 5
    base = PlannerConfig(max_iterations=3000, eps=0.0)  # target: the straight line, never met
    unmet = math.dist(turning.start, turning.goal)
    trees = {}
    for label in ("eta=inf radius=shrinking goal=eta", "eta=10 radius=shrinking goal=eta",
                  "eta=10 radius=shrinking*0.01 goal=eta"):  # fmt: skip
        r = plan(turning.grid, turning.start, turning.goal, config=base.replace(**cells[label]),
                 keep_tree=True, seed=2, stop="optimal", reference_length=unmet)  # fmt: skip
        pts, par = r.tree_points, r.tree_parents
        child = np.flatnonzero(par >= 0)
        trees[label] = np.hypot(*(pts[child] - pts[par[child]]).T)
    assert trees["eta=inf radius=shrinking goal=eta"].max() > 20.0
    assert trees["eta=10 radius=shrinking goal=eta"].max() <= 10.0 + 1e-6
    small = trees["eta=10 radius=shrinking*0.01 goal=eta"]
    assert np.median(small) < np.median(trees["eta=10 radius=shrinking goal=eta"])


def test_a_perfect_path_heatmap_makes_nrrt_reach_the_optimum_in_far_fewer_iterations():
    """Fails if the oracle or its plumbing (source -> heatmap -> sampler) is wrong."""
    instances = [make_instance(m, k) for m in range(3) for k in range(2)]
    keys = [ConfigKey("rrt_star"), ConfigKey("nrrt_star", None, "oracle_path@s1")]
    table = run_trials(instances, keys, {("random", "optimal"): 3}, workers=1)
    assert table["success"].all()
    med = table.groupby("key")["iterations"].median()
    assert med["nrrt_star"] < 0.5 * med["rrt_star"], med.to_dict()
    assert table.loc[table["key"] == "nrrt_star", "heat_mass"].min() > 0.9


def test_taut_oracles_are_measured_against_the_exact_path(turning):
    every = everywhere(turning)
    heat = instance_heatmap("oracle_taut_vertex@s1", turning, None, 0.0, every)
    assert mass_near(heat, target_mask(turning, "taut_vertices"), 3.0) > 0.9
    heat = instance_heatmap("oracle_taut_path@s1", turning, None, 0.0, every)
    assert mass_near(heat, target_mask(turning, "taut_path"), 3.0) > 0.9


def test_the_cell_with_the_protocols_own_settings_is_left_out(turning):
    """A grid cell whose overrides all equal the protocol's settings would repeat the
    protocol cell's runs exactly (the same planner settings and seeds: the same result, checked
    through plan()); it is left out of the grid and of the evaluation, and only it."""
    rc = RegimeConfig(etas=[10.0, 20.0], radius_modes=["shrinking", "fixed1"],
                      gamma_factors=[1.0, 0.5], goal_radii=[None, math.inf])  # fmt: skip
    base = PlannerConfig(max_iterations=2000, eps=0.0)  # target: the straight line, never met
    every, cells = regime_cells(rc, ELSEWHERE), regime_cells(rc, protocol_settings(base))
    twin = "eta=10 radius=shrinking goal=eta"
    assert set(every) - set(cells) == {twin} and len(cells) == len(every) - 1 == 11
    assert base.replace(**every[twin]) == base
    runs = [plan(turning.grid, turning.start, turning.goal, config=c, seed=3, stop="optimal",
                 reference_length=math.dist(turning.start, turning.goal))
            for c in (base, base.replace(**every[twin]))]  # fmt: skip
    assert runs[0].iterations == runs[1].iterations and runs[0].cost == runs[1].cost
    ev = Configurations(sources={"vnrrt_star": "vertexnet"}, informed=False)
    env = {"optimal": {"path": "nrrt_star~0.5[oracle_path@s2]"}}
    oc = OracleConfig(blend_weights=[0.0], qualities=[1.0])
    keys = evaluation_keys(env, oc, rc, ev, protocol_settings(base))
    assert twin not in keys and set(keys) == {"protocol", *cells}
    fixed = regime_cells(rc, protocol_settings(base.replace(radius_mode="fixed")))
    assert "eta=10 radius=fixed1 goal=eta" not in fixed and twin in fixed  # fixed_radius 10
