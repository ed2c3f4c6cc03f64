"""plan(): paths, costs, stop rules and determinism against independent references."""

import functools
import itertools
import math
import types

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
    core,
    make_sampler,
    plan,
    polyline_length,
    run,
    segment_free,
)
from vnrrt.planners import tree as nodes
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


@pytest.fixture(params=["c", "python"])
def answers(request, monkeypatch) -> types.SimpleNamespace:
    """The free straight segment's answer function in use (``kind``: the C one of
    :mod:`vnrrt.planners.native`, or :func:`run.free_answer`), wrapped to record its
    ``calls``; the C one must be built here (a compiler is part of the setup)."""
    from vnrrt.planners import api, native

    real = native.answerer() if request.param == "c" else run.free_answer
    assert (real is not run.free_answer) is (request.param == "c"), "the C answer is not built"
    seen = types.SimpleNamespace(kind=request.param, calls=[])
    monkeypatch.setattr(api, "answerer", lambda: lambda *a: seen.calls.append(a) or real(*a))

    def recorded(fn):  # plan()'s and solve()'s common forms in C (which test the segment
        def call(*args):  # when they answer other than None)
            answer = fn(*args)
            if answer is not None:
                seen.calls.append(args)
            return answer

        return call if request.param == "c" else native._not_built

    monkeypatch.setattr(api, "planned", recorded(native.planned))
    monkeypatch.setattr(api, "solved", recorded(native.solved))
    return seen


@pytest.mark.parametrize(
    ("stop", "reference", "seed", "extra", "fast"),
    [
        ("initial", None, 0, {}, True),
        ("initial", 30.0, 7, {}, True),
        ("optimal", 30.0, 1, {}, True),
        ("optimal", 6, 2, {}, True),  # an int reference
        ("optimal", np.float64(30.0), 3, {}, False),  # not the common form: the general path
        ("optimal", None, 4, {}, False),  # the reference computed (A*)
        ("initial", None, 5, {"milestones": (3.0, 10.0)}, False),
        ("initial", None, 6, {"keep_tree": True}, False),
        ("initial", None, 6, {"milestones": np.array([3.0, 10.0])}, None),  # an error, as before
        ("initial", None, np.int64(8), {}, True),
        ("initial", None, (8, 1), {}, True),
        ("initial", None, (8, -1), {}, False),  # refused by the general path (a ValueError)
    ],
)  # (a reference below the segment's length is an error now: tests/test_planners_arguments.py)
def test_a_free_segments_one_pass_answer_is_the_general_paths(
    grid, heat, monkeypatch, answers, stop, reference, seed, extra, fast
):
    """The one-pass answer to a free straight segment of plan() and of Planner.solve
    (:func:`api._free_segment`, with the C answer and the Python one) is the general path's
    (the query checked, then the run) field by field, times apart; it is taken for the common
    form of the arguments only (the general path is not entered then). With the C answer, the
    common form whose segment does not answer goes to the run without the general path's
    checks too (made in C: api._common)."""
    from vnrrt.planners import api

    cfg = PlannerConfig(straight_first=True)
    s, e = (10.5, 10.5), (15.5, 12.5)
    ask = {"stop": stop, "reference_length": reference, "seed": seed, **extra}
    ordered = (stop, reference, seed, extra.get("milestones", ()), extra.get("keep_tree", False))
    if not api._seed_ok(seed) or fast is None:
        with pytest.raises(ValueError, match="seed|ambiguous"):
            plan(grid, s, e, config=cfg, **ask)
        with pytest.raises(GridError):  # the points checked first: the general path's order
            plan(grid, s, (99.5, 50.5), config=cfg, **ask)
        return
    for planner, hm in (("rrt_star", None), ("vnrrt_star", np.zeros_like(heat))):
        p = Planner(grid, planner, heatmap=hm, config=cfg)  # an all-zero heatmap: the fallback
        query, tested = api._query(p.occ, cfg, s, e, *ordered, p.setup_time,
                                   p.sampler.fallback_uniform)  # fmt: skip
        general = p._run(query, seed, tested)
        entered, real = [], api._query
        monkeypatch.setattr(
            api, "_query", lambda *a, n=entered, q=real, **k: n.append(1) or q(*a, **k)
        )
        answers.calls.clear()
        results = [p.solve(s, e, **ask)]
        if planner == "rrt_star":
            results.append(plan(grid, s, e, config=cfg, **ask))
        monkeypatch.setattr(api, "_query", real)
        common = fast or (answers.kind == "c" and (stop, reference) == ("optimal", 5.0))
        assert len(entered) == (0 if common else len(results))
        assert len(answers.calls) == len(results) or not fast  # the answer function's
        for r in results:
            assert same_run(r, general) and type(r.cost) is type(general.cost)
            assert [m.bound for m in r.milestones] == [m.bound for m in general.milestones]
            assert r.fallback_uniform is general.fallback_uniform is (planner == "vnrrt_star")
            if fast:  # the straight answer: the one segment test timed
                assert (r.iterations, r.tree_size) == (0, 2)
                assert 0 < r.time_to_first == r.time_to_stop
        assert results[0].setup_time == p.setup_time  # plan()'s RRT*: 0, no sampler built


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


def test_one_shot_plans_reuse_a_pooled_tree_and_give_the_same_results(grid, monkeypatch):
    """plan() takes its tree's arrays from run.POOL and gives them back: the second call on a
    map of the same shape allocates nothing, answers exactly as a fresh tree does, and shares
    no array with the first call's result; a tree that grew is not kept."""
    run.POOL.clear()
    made = []
    new_tree = nodes.new_tree
    monkeypatch.setattr(nodes, "new_tree", lambda c, *a: made.append(c) or new_tree(c, *a))
    cfg = PlannerConfig(max_iterations=3000)
    a = plan(grid, START, GOAL, stop="optimal", seed=3, config=cfg)
    path, trace = a.path.copy(), a.trace_costs.copy()
    b = plan(grid, START, GOAL, stop="optimal", seed=3, config=cfg)
    assert len(made) == 1  # the second call reused the first one's tree
    np.testing.assert_array_equal(a.path, path)  # not overwritten by the second run
    np.testing.assert_array_equal(a.trace_costs, trace)
    c = Planner(grid, config=cfg).solve(START, GOAL, stop="optimal", seed=3)  # its own tree
    assert len(made) == 2
    for r in (b, c):
        assert (r.cost, r.iterations, r.tree_size, r.collision_checks) == (
            a.cost, a.iterations, a.tree_size, a.collision_checks)  # fmt: skip
        np.testing.assert_array_equal(r.path, a.path)
    run.POOL.clear()
    big = PlannerConfig(max_iterations=20_000, eps=0.0)  # the straight line: never met
    r = plan(grid, START, GOAL, stop="optimal", reference_length=math.dist(START, GOAL), seed=0,
             config=big)  # fmt: skip
    assert r.tree_size > run.FIRST_CAPACITY  # it grew, so it was not given back
    assert run.POOL.take((run.FIRST_CAPACITY, grid.shape, 5.0, big.trace_capacity)) is None


def test_a_one_shot_plan_makes_its_settings_once_per_config_and_shape(grid, monkeypatch):
    """plan()'s common form that needs a tree (the straight segment blocked, tested in C)
    runs without a Planner: its settings are made once per config object and map shape and
    kept for the last settings.KEEP of them (with the config and sampler whose ids key
    them), its tree's arrays come from run.POOL and go back; a heatmap sampler's settings
    are not kept; the results are a Planner's."""
    from vnrrt.planners import FASTEST, settings

    monkeypatch.setattr(settings, "KEPT", {})
    made, real = [], settings.Settings
    monkeypatch.setattr(settings, "Settings", lambda *a: made.append(a) or real(*a))
    planners = []
    init = Planner.__init__
    monkeypatch.setattr(
        Planner, "__init__", lambda p, *a, **k: planners.append(1) or init(p, *a, **k)
    )
    ask = {"stop": "optimal", "reference_length": 170.0, "seed": 4}
    cfg = FASTEST.replace(max_iterations=5000)
    run.POOL.clear()
    a, b = plan(grid, START, GOAL, config=cfg, **ask), plan(grid, START, GOAL, config=cfg, **ask)
    assert a.iterations > 0 and (len(made), len(planners)) == (1, 0)  # a tree, no Planner
    assert run.POOL.take((run.FIRST_CAPACITY, grid.shape, 10.0, cfg.trace_capacity)) is not None
    solved = Planner(grid, config=cfg).solve(START, GOAL, **ask)
    for r in (b, solved):
        assert (r.path.tolist(), r.cost, r.iterations, r.collision_checks) == (
            a.path.tolist(), a.cost, a.iterations, a.collision_checks)  # fmt: skip
    plan(grid, START, GOAL, config=cfg.replace(eta=cfg.eta), **ask)  # equal values, new object
    assert len(made) == 2
    for k in range(settings.KEEP + 3):
        plan(grid, START, GOAL, config=cfg.replace(max_iterations=100 + k), **ask)
    assert len(settings.KEPT) == settings.KEEP
    for (cid, sid, shape), (c, smp, _) in settings.KEPT.items():
        assert (cid, sid, shape) == (id(c), id(smp), grid.shape)
    kept = dict(settings.KEPT)
    Planner(grid, "vnrrt_star", heatmap=np.ones(grid.shape), config=cfg).solve(START, GOAL, **ask)
    assert kept == settings.KEPT  # a heatmap sampler's settings: its Planner's only


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
    """The settings a run hands the core (run.query_params of a Planner's setup) are the
    config's, the query's start and goal and the map's gamma, each written out here from
    the definitions (the free area counted cell by cell); the draws are the sampler's and
    the gap sampler's settings."""
    rng = np.random.default_rng(3)
    occ = (rng.random((37, 53)) < 0.2).astype(np.uint8)
    heat = None if planner == "rrt_star" else rng.random(occ.shape)
    p = Planner(occ, planner, heatmap=heat, config=cfg)
    setup = p._ready()
    free = sum(1 for v in occ.ravel().tolist() if v == 0)
    base = cfg.gamma if cfg.gamma is not None else 2 * math.sqrt(1.5) * math.sqrt(free / math.pi)
    want = {
        "eta": cfg.eta,
        "gamma": cfg.gamma_factor * base if cfg.radius_mode == "shrinking" else 0.0,
        "radius": cfg.fixed_radius,
        "goal_radius": cfg.eta if cfg.goal_radius is None else cfg.goal_radius,
        "sx": 1.5, "sy": 2.5, "gx": 30.25, "gy": 20.5,
        "min_spacing": cfg.min_spacing,
        "bucket": max(min(cfg.eta, 53) / 2, 1.0),
        "informed": cfg.informed,
        "refine": cfg.refine,
        "pull_parents": cfg.pull_parents,
        "refine_branches": cfg.refine_branches,
    }  # fmt: skip
    query = run.Query((1.5, 2.5), (30.25, 20.5), None, (), False, None, 0.0, False)
    for straight in (False, True):
        params, first = run.query_params(setup.params, query, straight)
        got = dict(zip(core.Params._fields, params, strict=True))
        assert got == pytest.approx(want, rel=1e-15) and got.keys() == want.keys()
        assert dict(zip(core.Params._fields, first, strict=True)) == pytest.approx(
            {**want, "goal_radius": math.inf} if straight else want, rel=1e-15)  # fmt: skip
    d = setup.draws
    assert setup.flat_draws == tuple(d)
    s = p.sampler
    assert (d.mix, d.last) == (s.draw_mix, max(s.last, 0))
    np.testing.assert_array_equal(d.cdf, s.cdf if s.cdf.size else np.zeros(1))
    assert (d.gap_share, d.gap_width, d.gap_after) == (cfg.gap_share, cfg.gap_width, cfg.gap_after)
    assert d.n_gaps == (-1 if cfg.gap_share > 0 else 0)
    assert setup.work.budget == (cfg.max_iterations, cfg.max_seconds, cfg.trace_capacity)


def test_the_tree_pool_is_bounded():
    pool = run.TreePool(keys=2, per_key=1)
    trees = [run.Tree(8, (4, 4), 1.0, 4) for _ in range(4)]
    pool.give("a", trees[0])
    pool.give("a", trees[1])  # over per_key: dropped
    pool.give("b", trees[2])
    pool.give("c", trees[3])  # over keys: the oldest key ("a") goes
    assert pool.take("a") is None
    assert pool.take("b") is trees[2] and pool.take("c") is trees[3]
    assert pool.take("b") is None


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
    sampler = make_sampler("m_vnrrt_star", grid.shape, heat, PlannerConfig(**built))
    args = {"planner": "m_vnrrt_star", "config": PlannerConfig(**config), **kwargs}
    with pytest.raises(ValueError, match=match):
        plan(grid, START, GOAL, sampler=sampler, **args)
    small = make_sampler("rrt_star", (100, 200))
    with pytest.raises(GridError, match="shape"):
        plan(grid, START, GOAL, sampler=small)


def test_a_finished_tree_gives_its_branch_segment_lengths_and_trace():
    """tree.finish on a hand-made tree: root (0, 0) -> (3, 4) -> goal (3, 10); the final cost
    is appended to the trace only when it is not the last point traced."""
    links = np.full((4, 4), -1, np.int64)
    links[1, nodes.PARENT], links[2, nodes.PARENT] = 0, 1
    pts = np.array([[0.0, 0.0], [3.0, 4.0], [3.0, 10.0], [9.0, 9.0]])
    cost = np.array([0.0, 5.0, 11.0, 99.0])
    iters, costs = np.array([7, 0, 0], np.int64), np.array([12.0, 0.0, 0.0])
    path, segs, trace_it, trace_cost = nodes.finish(links, pts, cost, 2, iters, costs, 1, 30)
    assert np.array_equal(path, pts[:3]) and path.dtype == np.float64
    assert segs.tolist() == [5.0, 6.0] and float(np.add.reduce(segs)) == polyline_length(path)
    assert trace_it.tolist() == [7, 30] and trace_cost.tolist() == [12.0, 11.0]
    costs[0] = 11.0  # the final cost already traced: nothing appended
    _, _, trace_it, trace_cost = nodes.finish(links, pts, cost, 2, iters, costs, 1, 30)
    assert trace_it.tolist() == [7] and trace_cost.tolist() == [11.0]
    path, segs, trace_it, trace_cost = nodes.finish(links, pts, cost, -1, iters, costs, 0, 30)
    assert path.shape == (0, 2) and segs.size == 0 and trace_it.size == trace_cost.size == 0


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


def test_the_planners_results_hold_every_field_and_no_other(grid, heat):
    """The planners build results without PlanResult.of's check of the keys
    (:func:`vnrrt.planners.result.made`): a straight answer (both ways), a search, and
    each with the tree kept hold exactly the dataclass's fields."""
    from vnrrt.planners.result import FIELDS

    cfg = PlannerConfig(straight_first=True)
    vnrrt = Planner(grid, "vnrrt_star", heatmap=heat, config=cfg)
    for keep in (False, True):
        for s, e in (((10.5, 10.5), (15.5, 12.5)), (START, GOAL)):
            for r in (plan(grid, s, e, config=cfg, keep_tree=keep), vnrrt.solve(s, e)):
                assert r.__dict__.keys() == FIELDS


def test_a_blocked_straight_segment_is_tested_once(grid, monkeypatch, answers):
    """A query whose straight segment is blocked goes from the one-pass check (the C answer or
    the Python one) to the search with the segment tested once (the general path reuses that
    test), by plan() and Planner.solve alike, with the same result as before."""
    cfg = PlannerConfig(straight_first=True)
    before = plan(grid, START, GOAL, config=cfg, stop="optimal", reference_length=200.0)
    calls, real = [], run.straight_test
    monkeypatch.setattr(run, "straight_test", lambda *a: calls.append(a) or real(*a))
    p = Planner(grid, config=cfg)
    for solve in (functools.partial(plan, grid, config=cfg), p.solve):
        calls.clear()
        answers.calls.clear()
        r = solve(START, GOAL, stop="optimal", reference_length=200.0)
        assert len(answers.calls) == 1 and r.iterations > 0 and same_run(r, before)
        assert len(calls) == (answers.kind == "python")  # the C answer tests it in C


SEEDS = (0, 7, -1, (), (1, 2), (1, -2), (0, 2**70), (True, 1), (np.int64(3), 1), [1, 2],
         [1, -1], (1.0,), ("a",), np.int64(2), np.int64(-2), True, 1.0, None, ((1,),))  # fmt: skip


@pytest.mark.parametrize("seed", SEEDS, ids=repr)
def test_the_seed_checks_fast_paths_agree_with_its_definition(seed):
    """``_seed_ok``'s fast paths (an int; a tuple of ints) answer as the definition does: an
    integer >= 0, or a tuple or list of them (numbers.Integral, so bools and numpy ints
    too)."""
    import numbers

    from vnrrt.planners import api

    parts = seed if isinstance(seed, tuple | list) else (seed,)
    expected = all(isinstance(s, numbers.Integral) and s >= 0 for s in parts)
    assert api._seed_ok(seed) is expected
