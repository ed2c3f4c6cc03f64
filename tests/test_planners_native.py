"""The C answer to a free straight segment (vnrrt.planners._straight, bound by
vnrrt.planners.native) against its Python version, run.free_answer."""

import gc
import logging
import math
import pickle
import subprocess
import sys
import time
import weakref

import numpy as np
import pytest

from vnrrt.planners import Planner, PlannerConfig, make_sampler, native, plan, run
from vnrrt.planners.result import FIELDS, PlanResult

TIMES = ("time_to_first", "time_to_stop")


@pytest.fixture(scope="module")
def c_answer():
    answer = native.answerer()
    assert answer is not run.free_answer, "the C answer is not built (make setup compiles it)"
    return answer


def random_map(rng, h: int, w: int, density: float) -> np.ndarray:
    """An ``(h, w)`` uint8 map of random rectangles covering about ``density`` of it."""
    occ = np.zeros((h, w), np.uint8)
    while occ.mean() < density:
        y, x = rng.integers(0, h), rng.integers(0, w)
        occ[y : y + rng.integers(1, 6), x : x + rng.integers(1, 6)] = 1
    return occ


def queries(rng, occ: np.ndarray, n: int):
    """``n`` argument tuples for an answer function: points anywhere on and around the map
    (some in obstacles, on the border, off the map, not finite), targets None or around the
    distance."""
    h, w = occ.shape
    odd = (math.nan, math.inf, -math.inf, 0.0, float(w), -3.5, 1e300)
    for k in range(n):
        xy = [rng.uniform(-1.0, w + 1.0), rng.uniform(-1.0, h + 1.0),
              rng.uniform(-1.0, w + 1.0), rng.uniform(-1.0, h + 1.0)]  # fmt: skip
        if k % 4 == 0:
            xy = [float(np.floor(v)) + 0.5 for v in xy]  # cell centres
        if k % 23 == 0:
            xy[k % 4] = odd[k % len(odd)]
        d = math.hypot(xy[2] - xy[0], xy[3] - xy[1])
        target = (None, d * 1.01, d * 0.99, d)[k % 4] if math.isfinite(d) else None
        yield (occ, *xy, target, "rrt_star", (None, 7, 3.5)[k % 3], float(k % 5), k % 2 == 1)


def assert_same_answer(a, b) -> None:
    """The same answer: ``(d, seconds)`` tuples with the same ``d``, or results equal field by
    field (times apart), with arrays of the same dtype, shape and values and scalars of the
    same type."""
    assert type(a) is type(b)
    if type(a) is tuple:
        assert a[0] == b[0] and a[1] >= 0 and b[1] >= 0
        return
    assert a.__dict__.keys() == b.__dict__.keys() == FIELDS
    for name in FIELDS - set(TIMES):
        x, y = getattr(a, name), getattr(b, name)
        assert type(x) is type(y), name
        if isinstance(x, np.ndarray):
            assert (x.dtype, x.shape, x.flags.writeable) == (y.dtype, y.shape, y.flags.writeable)
            np.testing.assert_array_equal(x, y, err_msg=name)
        else:
            assert x == y, name
    assert 0 < a.time_to_first == a.time_to_stop < 1.0


@pytest.mark.parametrize(("h", "w", "density"), [(40, 60, 0.1), (7, 90, 0.05), (90, 7, 0.2),
                                                 (2, 2, 0.0), (64, 64, 0.0)])  # fmt: skip
def test_the_c_answer_is_the_python_one(c_answer, h, w, density):
    """On random maps and queries (free, blocked, above or below the bound, bad endpoints,
    points off the map or not finite), the C answer is the Python one, times apart."""
    rng = np.random.default_rng(h * 1000 + w)
    occ = random_map(rng, h, w, density)
    kinds = set()
    for args in queries(rng, occ, 400):
        a, b = c_answer(*args), run.free_answer(*args)
        assert_same_answer(a, b)
        kinds.add("result" if type(a) is PlanResult else a[0] if a[0] < 0 else "over")
    assert {"result", "over", -2.0} <= kinds  # answers, segments above the bound, bad points
    assert (-1.0 in kinds) is (density > 0)  # blocked segments


def test_the_c_results_own_their_arrays_and_are_freed(c_answer):
    """Each result has arrays of its own, pickles and unpickles to the same answer, and is
    freed when dropped; repeated calls leave the reference counts of their arguments and of
    the shared fields as they were."""
    occ = np.zeros((30, 30), np.uint8)
    planner, reference, setup = "rrt_star", 12.5, 0.25
    args = (occ, 3.5, 4.5, 20.5, 9.5, None, planner, reference, setup, False)
    a, b = c_answer(*args), c_answer(*args)
    a.path[0, 0] = a.trace_costs[0] = -1.0
    a.trace_iterations[0] = 9
    assert b.path[0, 0] == 3.5 and b.trace_costs[0] == b.cost and b.trace_iterations[0] == 0
    assert_same_answer(pickle.loads(pickle.dumps(b)), b)
    dead = weakref.ref(a)
    del a
    gc.collect()
    assert dead() is None
    counts = [sys.getrefcount(x) for x in (planner, reference, setup, run.STRAIGHT, occ)]
    blocks = sys.getallocatedblocks()
    for _ in range(5000):
        c_answer(*args)
        c_answer(occ, 3.5, 4.5, 35.0, 9.5, None, planner, reference, setup, False)  # off-map
    assert sys.getallocatedblocks() - blocks < 100  # no object of a result left behind
    assert [sys.getrefcount(x) for x in (planner, reference, setup, run.STRAIGHT, occ)] == counts


def test_the_c_answer_times_its_test_on_perf_counters_clock(c_answer):
    """The C answer's time lies inside the perf_counter interval around its call, on a long
    segment test (a 4000 px map: a few us) and a short one."""
    occ = np.zeros((8, 4000), np.uint8)
    for gx in (3999.5, 2.5):
        t0 = time.perf_counter()
        r = c_answer(occ, 0.5, 0.5, gx, 7.5, None, "rrt_star", None, 0.0, False)
        span = time.perf_counter() - t0
        assert 0 < r.time_to_stop == r.time_to_first < span


def test_the_python_answer_is_used_where_the_c_one_is_missing_or_cannot_be_bound(
    monkeypatch, caplog
):
    """Without the extension, or when its kernel cannot be compiled or bound, the answer
    function is the Python one (said in the log), and plan() answers as before."""
    from vnrrt.planners import FASTEST, plan

    occ = np.zeros((20, 20), np.uint8)
    want = plan(occ, (1.5, 1.5), (17.5, 12.5), config=FASTEST)
    import vnrrt.planners

    monkeypatch.setitem(sys.modules, "vnrrt.planners._straight", None)  # not built
    monkeypatch.delattr(vnrrt.planners, "_straight", raising=False)
    with caplog.at_level(logging.INFO, logger="vnrrt.planners.native"):
        assert native.answerer.__wrapped__() is run.free_answer
    assert "not built" in caplog.text
    monkeypatch.undo()

    def broken(*args, **kwargs):
        raise RuntimeError("no compiler today")

    monkeypatch.setattr(native, "cfunc", broken)
    with caplog.at_level(logging.WARNING, logger="vnrrt.planners.native"):
        assert native.answerer.__wrapped__() is run.free_answer
    assert "could not be bound" in caplog.text and "no compiler today" in caplog.text
    from vnrrt.planners import api

    monkeypatch.setattr(api, "answerer", lambda: run.free_answer)
    monkeypatch.setattr(api, "planned", native._not_built)
    monkeypatch.setattr(api, "solved", native._not_built)
    got = plan(occ, (1.5, 1.5), (17.5, 12.5), config=FASTEST)
    assert (got.cost, got.iterations, got.path.tolist()) == (want.cost, 0, want.path.tolist())


@pytest.mark.parametrize(
    ("args", "match"),
    [
        ((np.zeros((9, 9)),), "uint8"),  # float64
        ((np.zeros((9, 9), np.uint8).T[:, ::2],), "C-contiguous"),
        ((np.zeros(81, np.uint8),), "2-D"),
        (([[0, 0], [0, 0]],), "ndarray"),
        ((np.zeros((9, 9), np.uint8), "a"), "real number"),
    ],
)
def test_the_c_answer_refuses_what_it_cannot_read(c_answer, args, match):
    """A grid that is not a C-contiguous 2-D uint8 ndarray, a point that is not a number or a
    wrong argument count raise TypeError (the planners pass only checked arguments)."""
    full = (*args, *(1.5, 1.5, 4.5, 4.5, None, "rrt_star", None, 0.0, False)[len(args) - 1 :])
    with pytest.raises(TypeError, match=match):
        c_answer(*full)
    with pytest.raises(TypeError, match="10 arguments"):
        c_answer(*full[:9])


def test_an_unbound_c_answer_raises_and_a_zero_address_is_refused():
    """Before bind() the C answer raises instead of calling nothing, and plan()'s answers None
    (plan() then takes its Python path); bind() refuses a zero kernel address (in a fresh
    process: this one's module is bound)."""
    code = (
        "import numpy as np\n"
        "from vnrrt.planners import _straight as s\n"
        "occ = np.zeros((4, 4), np.uint8)\n"
        "print(s.plan(occ, (1.5, 1.5), (2.5, 2.5), 'rrt_star', *[None] * 5, 0, (), False))\n"
        "print(s.solve(occ, (1.5, 1.5), (2.5, 2.5), 'initial', None, 0, (), False))\n"
        "for call in (lambda: s.answer(occ, 1.5, 1.5, 2.5, 2.5, None, 'p', None, 0.0, False),\n"
        "             lambda: s.bind(0, type, {}, type, type)):\n"
        "    try:\n"
        "        call()\n"
        "    except (RuntimeError, ValueError) as e:\n"
        "        print(type(e).__name__, e)\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.splitlines() == [
        "None",  # plan()'s C answer, unbound: the Python path
        "None",  # solve()'s
        "RuntimeError answer: no kernel bound (call bind first)",
        "ValueError bind: the kernel address is 0",
    ]


class Str(str):
    """A str subclass: not plan()'s common form (its Python path compares it)."""


class Config(PlannerConfig):
    """A PlannerConfig subclass: not plan()'s common form."""


class Sub(Planner):
    """A Planner subclass: not Planner.solve's common form."""


def outcome(fn, *args, **kwargs):
    """``fn(*args, **kwargs)``'s result, or its exception's type and message."""
    try:
        return fn(*args, **kwargs)
    except Exception as error:
        return type(error), str(error)


def assert_same_outcome(a, b) -> None:
    """The same exception, or results equal field by field (times and the measured setup
    time apart; milestones by bound and iteration), scalars of the same type."""
    assert type(a) is type(b)
    if type(a) is tuple:
        assert a == b
        return
    for name in FIELDS - {*TIMES, "setup_time", "milestones"}:
        x, y = getattr(a, name), getattr(b, name)
        assert type(x) is type(y), name
        if isinstance(x, np.ndarray):
            assert (x.dtype, x.shape) == (y.dtype, y.shape), name
            np.testing.assert_array_equal(x, y, err_msg=name)
        else:
            assert x == y or (x != x and y != y), name
    assert [(m.bound, m.iteration) for m in a.milestones] == [
        (m.bound, m.iteration) for m in b.milestones
    ]


ODD_SEEDS = [(1, 2), (), [1, 2], np.int64(3), True, (1, -2), -1, 2**70, (2**70,), 1.5]


def plan_arguments(rng, occ: np.ndarray, configs: list, n: int):
    """``n`` random argument sets of plan() on ``occ``, each argument mostly of the common form
    (free points as tuples of floats, RRT*, a validated config with straight_first, an int
    seed...) and otherwise of one of the forms plan()'s Python path reads or refuses."""
    h, w = occ.shape
    free = np.argwhere(occ == 0)
    grids = [occ, occ.astype(bool), np.asfortranarray(occ), occ.astype(np.int64), occ.tolist(),
             occ.view(np.dtype(np.uint8, metadata={"m": 1})), np.zeros(5, np.uint8),
             occ[:, :]]  # fmt: skip

    def pick(common, odd, p=0.75):
        return common if rng.random() < p else odd[rng.integers(len(odd))]

    def point():
        y, x = free[rng.integers(len(free))]
        x, y = float(x) + 0.5, float(y) + 0.5
        odd = [(np.float64(x), np.float64(y)), [x, y], np.array([x, y]), (np.float32(x), y),
               (int(x), int(y)), (True, y), (x, y, 1.0), (str(x), y), (math.nan, y),
               (math.inf, y), (1e308, 1e308), (10**400, y), (-x, y), (x + w, y), x]  # fmt: skip
        return pick((x, y), odd, 0.8)

    for _ in range(n):
        start, goal = point(), point()
        try:
            d = math.dist(start, goal)
        except (TypeError, ValueError, OverflowError):
            d = 10.0
        d = d if math.isfinite(d) else 10.0
        refs = [None, int(math.ceil(d)), 0, 0.0, -1.0, math.nan, math.inf, np.float64(d), True,
                10**400, "a", 0.5 * d, d]  # fmt: skip
        yield (
            pick(occ, grids, 0.85),
            start,
            goal,
            pick("rrt_star", ["nrrt_star", Str("rrt_star"), "bogus"], 0.9),
            {
                "heatmap": pick(None, [np.ones((h, w))], 0.95),
                "sampler": pick(None, [make_sampler("rrt_star", (h, w))], 0.95),
                "config": pick(configs[0], configs[1:], 0.7),
                "stop": pick(("initial", "optimal")[rng.integers(2)], ["best", Str("optimal")]),
                "reference_length": pick(d * rng.uniform(0.95, 1.2), refs, 0.6),
                "seed": pick(int(rng.integers(100)), ODD_SEEDS, 0.7),
                "milestones": pick((), [(3.0,), [], np.array([])], 0.9),
                "keep_tree": pick(False, [True, 0, None], 0.9),
            },
        )


def test_plans_c_answer_is_its_python_paths(c_answer, monkeypatch):
    """plan() with its common form answered in C (native.planned) answers as plan() in Python
    does, on random arguments of every form (valid or not: the same result, times apart, or
    the same error); the C one answers only the common form (RRT*, no heatmap or sampler, a
    validated config with straight_first, the grid used in place, points of two floats, ints
    or float64s, a float or int reference, an int seed or a tuple of them, no milestones,
    keep_tree False), which plan()'s Python path answers in one pass too."""
    from vnrrt.planners import api

    rng = np.random.default_rng(5)
    occ = random_map(rng, 24, 30, 0.04)  # sparse: many free segments
    base = PlannerConfig(straight_first=True, max_iterations=40)
    base.validate()
    configs = [
        base,
        base.replace(straight_first=False),
        base.replace(eps=0),
        base.replace(eps=np.float64(0.02)),
        Config(straight_first=True),
        None,
        "cfg",
    ]
    for c in configs[1:4]:
        c.validate()
    kinds = []
    for grid, start, goal, planner, kw in plan_arguments(rng, occ, configs, 1500):
        if type(kw["config"]) is PlannerConfig and rng.random() < 0.1:  # one not yet validated
            kw["config"] = kw["config"].replace(max_iterations=41)
        ordered = [kw[k] for k in ("heatmap", "config", "sampler", "stop", "reference_length",
                                   "seed", "milestones", "keep_tree")]  # fmt: skip
        pre = outcome(native.planned, grid, start, goal, planner, *ordered)
        with monkeypatch.context() as m:
            m.setattr(api, "planned", native._not_built)
            python = outcome(plan, grid, start, goal, planner, **kw)
        c = outcome(plan, grid, start, goal, planner, **kw)
        assert_same_outcome(c, python)
        kind = "none" if pre is None else type(pre).__name__
        kinds.append(kind)
        if kind == "PlanResult":
            assert_same_outcome(pre, python)
            assert (pre.iterations, pre.setup_time, python.setup_time) == (0, 0.0, 0.0)
        else:
            assert kind in ("none", "tuple"), pre  # never an error
    counts = {k: kinds.count(k) for k in set(kinds)}
    assert counts["PlanResult"] > 100 and counts["tuple"] > 60 and counts["none"] > 500, counts


def test_solves_c_answer_is_its_python_paths(c_answer, monkeypatch):
    """Planner.solve with its common form answered in C (native.solved) answers as solve() in
    Python does (the same result, times apart, or the same error), for planners of every kind
    (RRT*, a heatmap planner, one whose heatmap has no weight left, a config without
    straight_first or not validated, a subclass) and random queries of every form."""
    from vnrrt.planners import api

    rng = np.random.default_rng(6)
    occ = random_map(rng, 24, 30, 0.04)
    cfg = PlannerConfig(straight_first=True, max_iterations=40)
    heat = rng.random(occ.shape)
    planners = [Planner(occ, config=cfg), Planner(occ, "vnrrt_star", heatmap=heat, config=cfg),
                Planner(occ, "nrrt_star", heatmap=np.zeros_like(heat), config=cfg),
                Planner(occ, config=cfg.replace(straight_first=False)), Sub(occ, config=cfg),
                Planner(occ.astype(bool), config=cfg.replace(eps=0))]  # fmt: skip
    late = Planner(occ, config=cfg)
    object.__setattr__(late, "config", cfg.replace(max_iterations=41))  # not validated
    planners.append(late)
    kinds = []
    for _, start, goal, _, kw in plan_arguments(rng, occ, [cfg, cfg], 1200):
        p = planners[rng.integers(len(planners))]
        ask = {k: kw[k] for k in ("stop", "reference_length", "seed", "milestones", "keep_tree")}
        pre = outcome(native.solved, p, start, goal, *ask.values())
        with monkeypatch.context() as m:
            m.setattr(api, "solved", native._not_built)
            python = outcome(p.solve, start, goal, **ask)
        c = outcome(p.solve, start, goal, **ask)
        assert_same_outcome(c, python)
        if type(c) is PlanResult:
            assert c.setup_time == python.setup_time == p.setup_time
        kinds.append(type(pre).__name__)
        if type(pre) is PlanResult:
            assert_same_outcome(pre, python)
            assert pre.setup_time == p.setup_time and type(p) is Planner
        else:
            assert pre is None or type(pre) is tuple, pre  # never an error
    counts = {k: kinds.count(k) for k in set(kinds)}
    assert counts["PlanResult"] > 60 and counts["tuple"] > 30 and counts["NoneType"] > 300, counts


def test_plans_c_answer_leaves_nothing_behind(c_answer):
    """plan()'s and solve()'s C answers (a result, a tested segment's tuple, None for another
    form) leave no object behind over repeated calls and the reference counts of their
    arguments as they were; they refuse a wrong argument count."""
    occ = np.zeros((30, 30), np.uint8)
    occ[10:20, 15] = 1
    cfg = PlannerConfig(straight_first=True)
    cfg.validate()
    start, free, blocked, ref = (3.5, 14.5), (12.5, 3.5), (25.5, 14.5), 40.0
    calls = [(free, "optimal", ref), (blocked, "optimal", ref), (free, "optimal", 2.0),
             (free, "initial", None), (free, "best", ref)]  # fmt: skip
    kinds = [type(native.planned(occ, start, g, "rrt_star", None, cfg, None, stop, r, (1, 2),
                                 (), False)) for g, stop, r in calls]  # fmt: skip
    assert kinds == [PlanResult, tuple, tuple, PlanResult, type(None)]
    watched = (occ, cfg, cfg.__dict__, start, free, blocked, ref)
    counts = [sys.getrefcount(x) for x in watched]
    blocks = sys.getallocatedblocks()
    for _ in range(3000):
        for g, stop, r in calls:
            native.planned(occ, start, g, "rrt_star", None, cfg, None, stop, r, (1, 2), (), False)
    del g, stop, r  # the loop's names
    assert sys.getallocatedblocks() - blocks < 100
    assert [sys.getrefcount(x) for x in watched] == counts
    p = Planner(occ, "vnrrt_star", heatmap=np.ones((30, 30)), config=cfg)
    kinds = [type(native.solved(p, start, g, stop, r, 3, (), False)) for g, stop, r in calls]
    assert kinds == [PlanResult, tuple, tuple, PlanResult, type(None)]
    watched = (p, p.__dict__, p.sampler, p.planner, p.setup_time, *watched)
    counts = [sys.getrefcount(x) for x in watched]
    blocks = sys.getallocatedblocks()
    for _ in range(3000):
        for g, stop, r in calls:
            native.solved(p, start, g, stop, r, 3, (), False)
    del g, stop, r
    assert sys.getallocatedblocks() - blocks < 100
    assert [sys.getrefcount(x) for x in watched] == counts
    with pytest.raises(TypeError, match="12 arguments"):
        native.planned(occ, start, free)
    with pytest.raises(TypeError, match="8 arguments"):
        native.solved(p, start, free)
