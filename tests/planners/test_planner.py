"""plan(): paths, costs, stop rules and determinism against independent references."""

import functools
import itertools
import math

import numpy as np
import pytest

from vnrrt.grid import GridError
from vnrrt.planners import (
    PLANNERS,
    Planner,
    PlannerConfig,
    PlannerConfigError,
    any_angle_length,
    astar_length,
    make_sampler,
    plan,
    polyline_length,
    rrt_star,
    segment_free,
)
from vnrrt.search import NoPathError, astar

START, GOAL = (20.5, 30.5), (180.5, 40.5)


def sampled_path_free(grid, path, step=0.01) -> bool:
    """Independent check: points every ``step`` px along each segment lie in free cells."""
    for p0, p1 in itertools.pairwise(path):
        n = int(np.ceil(np.hypot(*(p1 - p0)) / step)) + 1
        pts = p0 + np.linspace(0.0, 1.0, n)[:, None] * (p1 - p0)
        cells = np.floor(pts).astype(int)
        h, w = grid.shape
        inside = (cells >= 0).all() and (cells[:, 0] < w).all() and (cells[:, 1] < h).all()
        if not inside or grid[cells[:, 1], cells[:, 0]].any():
            return False
    return True


def wall_map() -> np.ndarray:
    """200x200: a vertical wall at x = 98..101 with a 10 px gap at y = 95..104."""
    g = np.zeros((200, 200), np.uint8)
    g[:, 98:102] = 1
    g[95:105, 98:102] = 0
    return g


def heatmap_for(grid, start, goal) -> np.ndarray:
    """A plausible learned heatmap: high on the A* path's cells, low elsewhere."""
    cells = np.floor([start, goal]).astype(int)
    path, _ = astar(grid, cells[0], cells[1])
    hm = np.full(grid.shape, 0.02)
    hm[path[:, 1], path[:, 0]] = 0.95
    return hm


@pytest.fixture(scope="module")
def grid():
    return wall_map()


@pytest.fixture(scope="module")
def heat(grid):
    return heatmap_for(grid, START, GOAL)


def kwargs_for(planner, heat, **settings):
    """The heatmap and config arguments of ``planner`` (M-VNRRT* masks below tau 0.5)."""
    config = PlannerConfig(tau=0.5, **settings)
    return {"config": config} if planner == "rrt_star" else {"heatmap": heat, "config": config}


def check_path(grid, r, start, goal):
    assert r.success and r.stop_reason == "solved"
    assert np.array_equal(r.path[0], start) and np.array_equal(r.path[-1], goal)
    assert sampled_path_free(grid, r.path)
    seg = np.hypot(*np.diff(r.path, axis=0).T).sum()
    assert r.cost == pytest.approx(seg, rel=1e-12)
    assert r.cost >= math.dist(start, goal) - 1e-9
    assert r.trace_costs[-1] == pytest.approx(r.cost, rel=1e-9)
    assert np.all(np.diff(r.trace_costs) <= 1e-9) and np.all(np.diff(r.trace_iterations) >= 0)
    assert 0 < r.time_to_first <= r.time_to_stop
    assert r.first_iteration <= r.iterations and r.tree_size <= r.iterations + 2


@pytest.mark.parametrize("planner", PLANNERS)
def test_initial_solution_is_valid(grid, heat, planner):
    r = plan(grid, START, GOAL, planner, stop="initial", seed=3, **kwargs_for(planner, heat))
    check_path(grid, r, START, GOAL)
    assert r.first_cost == pytest.approx(r.cost)


@pytest.mark.parametrize("planner", PLANNERS)
def test_optimal_within_one_percent_of_astar(grid, heat, planner):
    r = plan(grid, START, GOAL, planner, stop="optimal", seed=4, **kwargs_for(planner, heat))
    check_path(grid, r, START, GOAL)
    ref = astar_length(grid, START, GOAL)
    assert r.reference_length == pytest.approx(ref)
    assert r.cost <= 1.01 * ref


def test_any_angle_reference_and_milestones(grid):
    tight = any_angle_length(grid, START, GOAL)
    loose = astar_length(grid, START, GOAL)
    assert math.dist(START, GOAL) < tight < loose
    r = plan(grid, START, GOAL, stop="optimal", config=PlannerConfig(reference="any_angle"),
             milestones=(1.01 * loose,))  # fmt: skip
    check_path(grid, r, START, GOAL)
    assert r.cost <= 1.01 * tight
    (m,) = r.milestones
    assert m.reached and r.time_to_first <= m.time <= r.time_to_stop


def test_random_rectangles_map():
    rng = np.random.default_rng(0)
    g = np.zeros((120, 120), np.uint8)
    for x, y, w, h in rng.integers([0, 0, 5, 5], [110, 110, 25, 25], size=(14, 4)):
        g[y : y + h, x : x + w] = 1
    g[:12, :12] = g[-12:, -12:] = 0
    r = plan(g, (5.5, 5.5), (114.5, 114.5), stop="optimal", seed=1)
    check_path(g, r, (5.5, 5.5), (114.5, 114.5))
    assert r.cost <= 1.01 * astar_length(g, (5.5, 5.5), (114.5, 114.5))


def test_same_seed_same_result(grid, heat):
    a = plan(grid, START, GOAL, "vnrrt_star", heatmap=heat, stop="optimal", seed=12)
    b = plan(grid, START, GOAL, "vnrrt_star", heatmap=heat, stop="optimal", seed=12)
    c = plan(grid, START, GOAL, "vnrrt_star", heatmap=heat, stop="optimal", seed=13)
    assert np.array_equal(a.path, b.path) and a.iterations == b.iterations
    assert np.array_equal(a.trace_costs, b.trace_costs) and a.collision_checks == b.collision_checks
    assert a.iterations != c.iterations or not np.array_equal(a.path, c.path)


def test_tree_edges_are_free(grid):
    r = plan(grid, START, GOAL, stop="initial", seed=2, keep_tree=True)
    pts, par = r.tree_points, r.tree_parents
    assert len(pts) == r.tree_size and par[0] == -1 and (par[1:] >= 0).all()
    assert all(segment_free(grid, *pts[par[i]], *pts[i]) for i in range(1, len(pts)))


def test_budgets_are_failures_not_exceptions(grid):
    r = plan(grid, START, GOAL, stop="initial", config=PlannerConfig(max_iterations=30))
    assert not r.success and r.stop_reason == "max_iterations" and r.iterations == 30
    assert r.path.shape == (0, 2) and math.isinf(r.cost) and math.isnan(r.time_to_first)
    # the straight-line length at eps 0: a target no tree path (with a turn) meets
    r = plan(grid, START, GOAL, stop="optimal", reference_length=math.dist(START, GOAL),
             config=PlannerConfig(max_seconds=0.05, eps=0.0))  # fmt: skip
    assert not r.success and r.stop_reason == "max_seconds" and r.path.shape[1] == 2


@pytest.mark.parametrize(
    "settings",
    [{"radius_mode": "fixed", "fixed_radius": 15.0}, {"goal_radius": 3.0, "eta": 5.0},
     {"gamma": 50.0}, {"mix": 1.0}],
)  # fmt: skip
def test_config_variants_still_valid(grid, heat, settings):
    r = plan(grid, START, GOAL, "nrrt_star", heatmap=heat, stop="optimal", seed=5,
             config=PlannerConfig(**settings))  # fmt: skip
    check_path(grid, r, START, GOAL)
    assert r.cost <= 1.01 * astar_length(grid, START, GOAL)


def test_direct_line_of_sight_is_immediate(grid):
    r = plan(grid, (10.5, 10.5), (15.5, 12.5), stop="optimal")
    assert r.success and r.iterations == 0 and len(r.path) == 2
    assert r.cost == pytest.approx(math.dist((10.5, 10.5), (15.5, 12.5)))


def test_masked_fallback_is_recorded(grid, heat):
    r = plan(grid, START, GOAL, "m_vnrrt_star", heatmap=heat, config=PlannerConfig(tau=5.0),
             seed=1)  # fmt: skip
    assert r.success and r.fallback_uniform


@pytest.mark.parametrize(
    ("args", "kwargs", "error", "match"),
    [
        (((99.5, 50.5), GOAL), {}, GridError, "obstacle"),
        (((-1.0, 50.5), GOAL), {}, GridError, "outside"),
        ((START, (200.5, 10.5)), {}, GridError, "outside"),
        (((0.0, 50.5), GOAL), {}, GridError, "border"),
        (((float("nan"), 1.0), GOAL), {}, GridError, "finite"),
        (((1.0,), GOAL), {}, GridError, r"start must be a finite point .* got \(1\.0,\)"),
        ((START, "ab"), {}, GridError, "goal must be a finite point .* got 'ab'"),
        ((START, None), {}, GridError, "goal must be a finite point"),
        ((START, GOAL, "vnrrt_star"), {"heatmap": np.ones((100, 200))}, GridError, "shape"),
        ((START, GOAL, "vnrrt_star"), {}, ValueError, "needs a heatmap"),
        ((START, GOAL, "rrt_star"), {"heatmap": np.ones((200, 200))}, ValueError, "no heatmap"),
        ((START, GOAL, "astar_star"), {}, ValueError, "unknown planner"),
        ((START, GOAL), {"stop": "best"}, ValueError, "stop rule"),
        ((START, GOAL), {"config": PlannerConfig(eta=-1.0)}, PlannerConfigError, "eta"),
        ((START, GOAL), {"config": {"eta": 1.0}}, TypeError, "PlannerConfig"),
        ((START, GOAL), {"eta": 1.0}, TypeError, "eta"),
        ((START, GOAL), {"tau": 0.5}, TypeError, "tau"),
        ((START, GOAL), {"seed": -1}, ValueError, "seed"),
        ((START, GOAL), {"seed": (1, 2.5)}, ValueError, "seed"),
        (
            (START, GOAL),
            {"reference_length": math.nan, "stop": "optimal"},
            ValueError,
            "reference_length",
        ),
    ],
)
def test_bad_input_gives_clear_error(grid, args, kwargs, error, match):
    with pytest.raises(error, match=match):
        plan(grid, *args, **kwargs)


def test_disconnected_optimal_needs_a_path():
    g = wall_map()
    g[95:105, 98:102] = 1
    with pytest.raises(NoPathError):
        plan(g, START, GOAL, stop="optimal")
    r = plan(g, START, GOAL, stop="initial", config=PlannerConfig(max_iterations=2000))
    assert not r.success


@pytest.mark.parametrize("planner", PLANNERS)
@pytest.mark.parametrize("seed", range(5))
def test_optimal_any_angle_many_seeds(grid, heat, planner, seed):
    kw = kwargs_for(planner, heat, reference="any_angle")
    r = plan(grid, START, GOAL, planner, stop="optimal", seed=seed, **kw)
    check_path(grid, r, START, GOAL)
    assert r.cost <= 1.01 * any_angle_length(grid, START, GOAL)


def shapes_map(seed: int) -> tuple[np.ndarray, tuple, tuple]:
    """200x200 with random rectangles and discs; endpoints in opposite free corners."""
    rng = np.random.default_rng(seed)
    g = np.zeros((200, 200), np.uint8)
    yy, xx = np.mgrid[:200, :200]
    for x, y, a, b in rng.integers([0, 0, 8, 8], [200, 200, 40, 40], size=(14, 4)):
        if a % 2:
            g[y : y + b, x : x + a] = 1
        else:
            g[(xx - x) ** 2 + (yy - y) ** 2 <= (a // 2) ** 2] = 1
    g[:15, :15] = g[-15:, -15:] = 0
    return g, (5.5, 5.5), (194.5, 194.5)


@pytest.mark.slow
@pytest.mark.parametrize("planner", PLANNERS)
@pytest.mark.parametrize("seed", range(30))
def test_random_maps_all_planners(planner, seed):
    g, s, e = shapes_map(seed)
    try:
        tight = any_angle_length(g, s, e)
    except NoPathError:
        pytest.skip("corners not connected on this map")
    kw = kwargs_for(planner, heatmap_for(g, s, e), reference="any_angle")
    first = plan(g, s, e, planner, seed=seed, **kw)
    check_path(g, first, s, e)
    best = plan(g, s, e, planner, stop="optimal", seed=seed, **kw)
    check_path(g, best, s, e)
    assert best.cost <= 1.01 * tight <= 1.01 * astar_length(g, s, e)


@pytest.mark.parametrize("spacing", [0.0, 0.5])
def test_min_spacing_stops_nodes_piling_up_under_a_concentrated_heatmap(grid, spacing):
    """M-VNRRT* on a heatmap with one hot pixel draws half its samples inside that pixel.
    With ``min_spacing`` s, a node added from such a sample is at least s from every node,
    so the pixel holds at most 9 nodes for s = 0.5 (3 x 3 at spacing 0.5); without it,
    hundreds pile up there."""
    hot = np.zeros(grid.shape)
    hx, hy = 20, 20
    hot[hy, hx] = 1.0
    # the straight-line length at eps 0: never reached, so the run takes all 4,000 iterations
    cfg = PlannerConfig(tau=0.5, min_spacing=spacing, max_iterations=4000, eps=0.0)
    r = plan(grid, (5.5, 5.5), (54.5, 54.5), "m_vnrrt_star", heatmap=hot, config=cfg,
             stop="optimal", reference_length=math.dist((5.5, 5.5), (54.5, 54.5)), seed=3,
             keep_tree=True)  # fmt: skip
    pts = r.tree_points
    inside = (np.floor(pts[:, 0]) == hx) & (np.floor(pts[:, 1]) == hy)
    if spacing > 0:
        assert inside.sum() <= 9
        near = pts[inside]
        gaps = np.hypot(*(near[:, None] - near[None]).transpose(2, 0, 1))
        assert (gaps[~np.eye(len(near), dtype=bool)] >= spacing - 1e-9).all()
    else:
        assert inside.sum() > 100


def test_min_spacing_must_be_below_the_steer_step(grid):
    with pytest.raises(PlannerConfigError, match="min_spacing"):
        plan(grid, (5.5, 5.5), (54.5, 54.5), config=PlannerConfig(min_spacing=20.0))


@pytest.mark.parametrize("planner", PLANNERS)
def test_a_planner_set_up_once_answers_as_plan_does(grid, heat, planner):
    """One Planner (grid, sampler and settings checked once) solving several queries gives,
    per seed, exactly what a plan() call gives."""
    kw = kwargs_for(planner, heat, straight_first=True, informed=True)
    once = Planner(grid, planner, **kw)
    queries = [(START, GOAL), (GOAL, START), ((10.5, 10.5), (15.5, 12.5))]  # the last: free
    for seed, ((s, e), keep) in enumerate(itertools.product(queries, (False, True))):
        ask = {"stop": "optimal", "seed": seed, "milestones": (20.0, 400.0), "keep_tree": keep}
        a, b = once.solve(s, e, **ask), plan(grid, s, e, planner, **ask, **kw)
        assert same_run(a, b)


TIMES = ("time_to_first", "time_to_stop", "setup_time", "milestones")


def same_run(a, b) -> bool:
    """Two results of one query and seed agree on every field that is not a time (and on
    which milestones were reached, at which iteration)."""
    for name in a.__dataclass_fields__:
        x, y = getattr(a, name), getattr(b, name)
        if name in TIMES:
            continue
        if isinstance(x, np.ndarray) or isinstance(y, np.ndarray):
            np.testing.assert_array_equal(x, y, err_msg=name)
        else:
            assert x == y, name
    reached = [(m.bound, m.iteration) for m in a.milestones]
    return reached == [(m.bound, m.iteration) for m in b.milestones]


FREE_START, FREE_GOAL = (10.5, 10.5), (15.5, 12.5)  # a free segment of 5.39 px


@pytest.mark.parametrize(
    ("stop", "reference", "seed", "extra"),
    [
        ("initial", None, 0, {}),
        ("initial", 30.0, 7, {}),
        ("optimal", 30.0, 1, {}),
        ("optimal", 6, 2, {}),  # an int reference
        ("optimal", np.float64(30.0), 3, {}),
        ("optimal", None, 4, {}),  # the reference computed (A*)
        ("initial", None, 5, {"milestones": (3.0, 10.0)}),
        ("initial", None, 6, {"keep_tree": True}),
        ("initial", None, np.int64(8), {}),
        ("initial", None, (8, 1), {}),
    ],
)  # (a reference below the segment's length is an error: tests/planners/test_arguments.py)
def test_a_free_straight_segment_is_the_answer_when_it_meets_the_stop_rule(
    grid, heat, stop, reference, seed, extra
):
    """With ``straight_first``, a free start-goal segment that meets the stop rule is the
    answer (the exact optimum): a two-node tree, its cost the distance, milestones reached at
    iteration 0 when above it, written out here from the definitions; one that does not
    meet it starts a search. plan() and Planner.solve answer alike, for every planner."""
    cfg = PlannerConfig(straight_first=True, max_iterations=2000)
    s, e = FREE_START, FREE_GOAL
    d = math.dist(s, e)
    ask = {"stop": stop, "reference_length": reference, "seed": seed, **extra}
    ref = astar_length(grid, s, e) if reference is None and stop == "optimal" else reference
    target = None if stop == "initial" else 1.01 * ref
    for planner, hm in (("rrt_star", None), ("vnrrt_star", np.zeros_like(heat))):
        p = Planner(grid, planner, heatmap=hm, config=cfg)  # an all-zero heatmap: the fallback
        r = p.solve(s, e, **ask)
        assert same_run(r, plan(grid, s, e, planner, heatmap=hm, config=cfg, **ask))
        assert r.reference_length == ref and r.target_cost == pytest.approx(target)
        assert r.fallback_uniform is (planner == "vnrrt_star") and r.setup_time == p.setup_time
        if target is not None and d > target:
            assert r.iterations > 0 and not r.success and r.cost >= d  # no path beats it
            continue
        assert (r.success, r.stop_reason, r.iterations, r.tree_size) == (True, "solved", 0, 2)
        assert r.path.tolist() == [list(s), list(e)] and r.cost == r.first_cost == d
        assert r.collision_checks == 1 and r.first_iteration == 0
        assert r.trace_iterations.tolist() == [0] and r.trace_costs.tolist() == [d]
        assert r.trace_iterations.dtype == np.int64 and type(r.cost) is float
        assert 0 < r.time_to_first == r.time_to_stop
        milestones = extra.get("milestones", ())
        assert [(m.bound, m.iteration) for m in r.milestones] == [
            (b, 0 if d <= b else -1) for b in milestones
        ]
        if extra.get("keep_tree"):
            assert r.tree_points.tolist() == [list(s), list(e)]
            assert r.tree_parents.tolist() == [-1, 0]
        else:
            assert r.tree_points is None and r.tree_parents is None


@pytest.mark.parametrize(
    ("args", "kwargs", "error", "match"),
    [
        (((99.5, 50.5), (15.5, 12.5)), {}, GridError, "obstacle"),
        (((0.0, 12.5), (15.5, 12.5)), {}, GridError, "border"),
        (((10.5, 10.5), (15.5, float("inf"))), {}, GridError, "finite"),
        (((10.5,), (15.5, 12.5)), {}, GridError, "start must be a finite point"),
        (((10.5, 10.5), ("a", "b")), {}, GridError, "goal must be a finite point"),
        (((10.5, 10.5), (15.5, 12.5)), {"stop": "best"}, ValueError, "stop rule"),
        (((10.5, 10.5), (15.5, 12.5)), {"seed": -1}, ValueError, "seed"),
        (((10.5, 10.5), (15.5, 12.5)), {"milestones": ("a",)}, ValueError, "could not convert"),
        (
            ((10.5, 10.5), (15.5, 12.5)),
            {"stop": "optimal", "reference_length": -1.0},
            ValueError,
            "reference_length",
        ),
    ],
)
def test_a_free_segment_is_answered_only_after_the_checks_of_a_search(grid, args, kwargs,
                                                                       error, match):  # fmt: skip
    """plan()'s RRT* answer to a free straight segment (no Planner built) refuses what
    Planner.solve refuses."""
    cfg = PlannerConfig(straight_first=True)
    with pytest.raises(error, match=match):
        plan(grid, *args, config=cfg, **kwargs)
    with pytest.raises(error, match=match):
        Planner(grid, config=cfg).solve(*args, **kwargs)


@pytest.mark.parametrize(
    "cfg",
    [
        PlannerConfig(),
        PlannerConfig(
            eta=20.0,
            informed=True,
            refine=0.5,
            pull_parents=True,
            refine_branches=0.25,
            gap_share=0.3,
            gap_width=5,
            gap_after=7,
            goal_radius=math.inf,
            min_spacing=1.5,
        ),
        PlannerConfig(radius_mode="fixed", fixed_radius=7.0, eta=math.inf),
        PlannerConfig(gamma=40.0, gamma_factor=0.5, eta=400.0, goal_radius=12.0),
    ],
)
@pytest.mark.parametrize("planner", ["rrt_star", "vnrrt_star"])
def test_a_runs_core_settings_are_its_configs_and_its_querys(cfg, planner):
    """The settings a Planner hands the core (its setup's Params, the query's start and goal
    filled in by each run) are the config's and the map's gamma, each written out here from
    the definitions (the free area counted cell by cell); the draws are the sampler's and
    the gap sampler's settings; the budgets are read from the config."""
    rng = np.random.default_rng(3)
    occ = (rng.random((37, 53)) < 0.2).astype(np.uint8)
    heat = None if planner == "rrt_star" else rng.random(occ.shape)
    p = Planner(occ, planner, heatmap=heat, config=cfg)
    setup = p.setup
    free = sum(1 for v in occ.ravel().tolist() if v == 0)
    base = cfg.gamma if cfg.gamma is not None else 2 * math.sqrt(1.5) * math.sqrt(free / math.pi)
    want = {
        "eta": cfg.eta,
        "gamma": cfg.gamma_factor * base if cfg.radius_mode == "shrinking" else 0.0,
        "radius": cfg.fixed_radius,
        "goal_radius": cfg.eta if cfg.goal_radius is None else cfg.goal_radius,
        "sx": 0.0, "sy": 0.0, "gx": 0.0, "gy": 0.0,
        "min_spacing": cfg.min_spacing,
        "bucket": max(min(cfg.eta, 53) / 2, 1.0),
        "informed": cfg.informed,
        "refine": cfg.refine,
        "pull_parents": cfg.pull_parents,
        "refine_branches": cfg.refine_branches,
    }  # fmt: skip
    got = setup.params._asdict()
    assert got == pytest.approx(want, rel=1e-15) and got.keys() == want.keys()
    d = rrt_star.Draws(*setup.draws)
    s = p.sampler
    assert (d.mix, d.last) == (0.0 if s.fallback_uniform else s.mix, max(s.last, 0))
    np.testing.assert_array_equal(d.cdf, s.cdf if s.cdf.size else np.zeros(1))
    assert (d.gap_share, d.gap_width, d.gap_after) == (cfg.gap_share, cfg.gap_width, cfg.gap_after)
    assert d.n_gaps == (-1 if cfg.gap_share > 0 else 0)
    assert setup.cfg is cfg and setup.occ is p.occ and setup.sampler is p.sampler


@pytest.mark.parametrize(
    ("built", "config", "kwargs", "match"),
    [
        ({"tau": 0.5}, {"tau": 0.9}, {}, "built with tau=0.5"),
        ({"mix": 0.5}, {"mix": 0.8}, {}, "built with mix=0.5"),
        ({}, {}, {"heatmap": np.ones((200, 200))}, "not both"),
        ({}, {}, {"planner": "vnrrt_star"}, "heatmap sampler, got a masked"),
    ],
)
def test_a_prebuilt_sampler_is_checked_against_the_config(grid, heat, built, config, kwargs, match):
    sampler = make_sampler("m_vnrrt_star", grid.shape, heat, config=PlannerConfig(**built))
    args = {"planner": "m_vnrrt_star", "config": PlannerConfig(**config), **kwargs}
    with pytest.raises(ValueError, match=match):
        plan(grid, START, GOAL, sampler=sampler, **args)
    small = make_sampler("rrt_star", (100, 200))
    with pytest.raises(GridError, match="shape"):
        plan(grid, START, GOAL, sampler=small)


@pytest.mark.parametrize("seed", range(3))
def test_a_result_costs_exactly_its_paths_polyline_length(grid, seed):
    """The cost returned is the polyline length of the path returned, to the last bit, solved
    or not; an unsolved run returns an empty path of infinite cost."""
    r = plan(
        grid, START, GOAL, stop="optimal", seed=seed, config=PlannerConfig(max_iterations=3000)
    )
    assert r.path.dtype == np.float64 and r.cost == polyline_length(r.path)
    assert r.trace_iterations.dtype == np.int64 and r.trace_iterations[-1] <= r.iterations
    short = plan(grid, START, GOAL, seed=seed, config=PlannerConfig(max_iterations=1))
    assert not short.success and short.path.shape == (0, 2) and short.cost == math.inf
    assert short.first_cost == math.inf and short.trace_costs.size == 0


def test_a_blocked_straight_segment_is_tested_once(grid, monkeypatch):
    """A query whose straight segment is blocked tests it once, then searches: by plan() and
    Planner.solve alike, with the same result as without ``straight_first``."""
    cfg = PlannerConfig(straight_first=True)
    ask = {"stop": "optimal", "reference_length": 200.0}
    before = plan(grid, START, GOAL, config=PlannerConfig(), **ask)
    calls, real = [], rrt_star.straight_cost
    monkeypatch.setattr(rrt_star, "straight_cost", lambda *a: calls.append(a) or real(*a))
    p = Planner(grid, config=cfg)
    for solve in (functools.partial(plan, grid, config=cfg), p.solve):
        calls.clear()
        r = solve(START, GOAL, **ask)
        assert len(calls) == 1 and r.iterations > 0 and same_run(r, before)


SEEDS = (0, 7, -1, (), (1, 2), (1, -2), (0, 2**70), (True, 1), (np.int64(3), 1), [1, 2],
         [1, -1], (1.0,), ("a",), np.int64(2), np.int64(-2), True, 1.0, None, ((1,),))  # fmt: skip


@pytest.mark.parametrize("seed", SEEDS, ids=repr)
def test_a_seed_is_accepted_exactly_when_it_is_one_by_definition(seed):
    """A seed is an integer >= 0, or a tuple or list of them (numbers.Integral, so bools and
    numpy ints too); anything else is refused with a ValueError naming the seed."""
    import numbers

    parts = seed if isinstance(seed, tuple | list) else (seed,)
    expected = all(isinstance(s, numbers.Integral) and s >= 0 for s in parts)
    occ = np.zeros((8, 8), np.uint8)
    if expected:
        assert plan(occ, (1.5, 1.5), (6.5, 5.5), seed=seed).success
    else:
        with pytest.raises(ValueError, match="seed"):
            plan(occ, (1.5, 1.5), (6.5, 5.5), seed=seed)
