"""Public entry points: :class:`Planner` (set up once per map, solved many times) and
:func:`plan` (one call).

Coordinates follow :mod:`vnrrt.grid`: ``grid`` is ``(H, W)`` indexed ``grid[y, x]``
(nonzero = obstacle), start and goal are continuous ``(x, y)`` pixel points (cell
centres ``(x + 0.5, y + 0.5)`` for dataset instances). Every setting comes from one
:class:`PlannerConfig` (the M-VNRRT* threshold ``tau`` included). Timings cover the tree
search and taking its path out (:mod:`.run`): building the sampler from a heatmap (per map,
once; reported as ``setup_time``), allocating the tree's arrays (per planner, reused; as
OMPL's ``setup()``), seeding, JIT compilation (once per process, :func:`warmup`) and the
reference-length computation (an oracle, not part of planning) are outside the timed region. With
``straight_first``, a free start-goal segment that meets the stop rule is the answer: the run's
time is that one segment test (:mod:`.run`). The gap sampler's cells (``gap_share``) are found
inside the run, after ``gap_after`` iterations.
"""

from __future__ import annotations

import functools
import logging
import math
import numbers
import time

import numpy as np

from vnrrt.grid import GridError, as_occupancy, as_point
from vnrrt.planners import core, run, settings
from vnrrt.planners.arguments import check_stop_target
from vnrrt.planners.collision import segment_free
from vnrrt.planners.config import PLANNERS, PlannerConfig
from vnrrt.planners.native import answerer, planned, solved
from vnrrt.planners.reference import reference_length as compute_reference
from vnrrt.planners.result import PlanResult
from vnrrt.planners.samplers import Sampler, heatmap_sampler, rng_state, uniform_sampler

log = logging.getLogger(__name__)
UINT8 = np.dtype(np.uint8)  # the one uint8 dtype object: an identity test is the fast check

DEFAULT = PlannerConfig()
SAMPLER_KINDS = {
    "rrt_star": "uniform",
    "nrrt_star": "heatmap",
    "vnrrt_star": "heatmap",
    "m_vnrrt_star": "masked",
}


def _known(planner: str) -> None:
    if planner not in PLANNERS:
        raise ValueError(f"unknown planner {planner!r}; choose from {PLANNERS}")


def _config(config: PlannerConfig | None) -> PlannerConfig:
    if config is None:
        return DEFAULT
    if not isinstance(config, PlannerConfig):
        raise TypeError(f"config must be a PlannerConfig, got {type(config).__name__}")
    config.validate()  # remembered: a frozen config is checked once
    return config


def make_sampler(
    planner: str, shape: tuple[int, int], heatmap=None, config: PlannerConfig | None = None
) -> Sampler:
    """The sampler of ``planner`` for an ``(H, W)`` map (see :mod:`.samplers`), built with
    ``config.mix`` and, for M-VNRRT*, ``config.tau``."""
    _known(planner)
    cfg = _config(config)
    if planner == "rrt_star":
        if heatmap is not None:
            raise ValueError("rrt_star samples uniformly and takes no heatmap")
        return uniform_sampler(shape)
    if heatmap is None:
        raise ValueError(f"{planner} needs a heatmap of shape {tuple(shape)}")
    tau = cfg.tau if planner == "m_vnrrt_star" else None
    return heatmap_sampler(heatmap, shape, cfg.mix, tau)


def check_sampler(
    sampler: Sampler, planner: str, shape: tuple[int, int], config: PlannerConfig
) -> None:
    """Raise ``ValueError`` unless ``sampler`` is what ``planner`` samples from on a map of
    ``shape`` with ``config`` (its kind, shape, ``mix`` and, when masked, ``tau``)."""
    want = SAMPLER_KINDS[planner]
    if sampler.kind != want:
        raise ValueError(f"{planner} samples from a {want} sampler, got a {sampler.kind} one")
    if tuple(sampler.shape) != tuple(shape):
        raise GridError(f"sampler is for shape {sampler.shape}, the grid has shape {shape}")
    if want != "uniform" and sampler.mix != config.mix:
        raise ValueError(f"sampler was built with mix={sampler.mix}, the config has {config.mix}")
    if want == "masked" and sampler.tau != config.tau:
        raise ValueError(f"sampler was built with tau={sampler.tau}, the config has {config.tau}")


def _occupancy(grid) -> np.ndarray:
    """``grid`` as the core reads it: a C-contiguous 2-D uint8 ``np.ndarray`` (at least 2x2;
    not a subclass) is used as it is (nonzero = obstacle, no copy); anything else goes through
    :func:`as_occupancy`."""
    if type(grid) is np.ndarray and grid.dtype is UINT8 and grid.ndim == 2:
        h, w = grid.shape
        if h >= 2 and w >= 2 and grid.flags.c_contiguous:
            return grid
    return as_occupancy(grid)


def _endpoint(occ: np.ndarray, point, name: str) -> tuple[float, float]:
    """``point`` as floats ``(x, y)``: finite, in a free cell, touching no obstacle or border."""
    try:
        x, y = point
        x, y = float(x), float(y)
    except (TypeError, ValueError):
        x = y = math.nan
    if math.isfinite(x) and math.isfinite(y) and segment_free(occ, x, y, x, y):
        return x, y
    as_point(occ, point, name)  # names a malformed point, one outside, one in an obstacle
    raise GridError(f"{name} {(x, y)} touches an obstacle cell or the map border")


def _floats(start, goal) -> tuple[float, float, float, float] | None:
    """``(sx, sy, gx, gy)`` as floats when ``start`` and ``goal`` are each two finite numbers,
    else None."""
    try:
        (sx, sy), (gx, gy) = start, goal
        sx, sy, gx, gy = float(sx), float(sy), float(gx), float(gy)
    except (TypeError, ValueError):
        return None
    return (sx, sy, gx, gy) if math.isfinite(sx + sy + gx + gy) else None


def _endpoints(occ: np.ndarray, start, goal, straight: bool):
    """:func:`_endpoint` of both points, and :func:`run.straight_test`'s answer (the
    straight segment tested when ``straight``): valid points are checked in that one
    compiled call. Returns ``(start, goal, tested)``."""
    xy = _floats(start, goal)
    if xy is not None:
        tested = run.straight_test(occ, *xy, straight)
        if tested[0] != core.BAD_ENDPOINT:
            return xy[:2], xy[2:], tested
    start, goal = _endpoint(occ, start, "start"), _endpoint(occ, goal, "goal")  # one raises
    return start, goal, run.straight_test(occ, *start, *goal, straight)


def _free_segment(
    occ: np.ndarray,
    cfg: PlannerConfig,
    start,
    goal,
    stop: str,
    reference_length,
    seed,
    milestones,
    keep_tree,
    planner: str = "rrt_star",
    setup_time: float = 0.0,
    fallback: bool = False,
) -> tuple[PlanResult | None, tuple | None]:
    """A solve's answer in one pass when ``cfg.straight_first`` holds, the straight segment is
    free and meets the stop rule, and the arguments have the common form: points of two
    numbers, ``stop`` ``'initial'`` or ``'optimal'`` with a ``reference_length`` (an int or
    float, finite and >= 0; optional for ``'initial'``), a valid seed, ``milestones`` the
    empty tuple and ``keep_tree`` false. ``planner``, ``setup_time`` and ``fallback`` go into
    the result, which is the general path's field by field (times apart; tested), without
    that path's layers (the query, the straight answer), each about a tenth of a call that
    one segment test answers.

    Returns ``(result, None)``, or ``(None, known)`` when the general path must answer
    (:func:`_query` then checks the arguments, raising their errors in its order, and the run
    plans): ``known`` is :func:`_endpoints`' ``(start, goal, tested)`` when the points passed
    the compiled test here (a blocked segment, one above the stop bound: ``_query`` reuses
    it, so the segment is tested once), else None."""
    if keep_tree or type(milestones) is not tuple or milestones:
        return None, None
    if stop not in ("initial", "optimal") or not _seed_ok(seed):
        return None, None
    if reference_length is None:
        if stop == "optimal":
            return None, None  # the reference is computed: the general path
        target = None
    elif type(reference_length) in (float, int) and 0 <= reference_length < math.inf:
        target = None if stop == "initial" else (1.0 + cfg.eps) * reference_length
    else:
        return None, None
    xy = _floats(start, goal)
    if xy is None:
        return None, None
    sx, sy, gx, gy = xy
    warmup()  # before the timed test: its kernel loaded
    answer = answerer()(occ, sx, sy, gx, gy, target, planner, reference_length, setup_time,
                        fallback)  # fmt: skip
    if type(answer) is tuple:  # blocked or above the bound: a tree
        return None, _tested(start, goal, answer)
    return answer, None


def _tested(start, goal, tested: tuple[float, float]) -> tuple | None:
    """:func:`_free_segment`'s ``known`` for points of the common form whose segment was
    tested (``tested``: :func:`run.straight_test`'s answer) and does not answer."""
    if tested[0] == core.BAD_ENDPOINT:
        return None  # an endpoint touching an obstacle: _query names it
    sx, sy, gx, gy = _floats(start, goal)
    return (sx, sy), (gx, gy), tested


def _common(cfg: PlannerConfig, start, goal, stop: str, reference_length, tested: tuple,
            setup_time: float = 0.0, fallback: bool = False) -> run.Query | None:  # fmt: skip
    """The query of a solve whose arguments :data:`planned` or :data:`solved` recognised in C
    as the common form (so checked there as :func:`_query` checks them: points of two finite
    numbers, the stop rule, an int or float reference, the seed, no milestones, no tree kept)
    and whose straight segment they tested (``tested``: ``(d, seconds)``, the segment blocked
    or above the stop bound); None when an endpoint touches an obstacle (:func:`_query` then
    names it). The compiled kernels are loaded (:func:`warmup`), as by :func:`_query`."""
    if tested[0] == core.BAD_ENDPOINT:
        return None
    warmup()
    sx, sy, gx, gy = _floats(start, goal)
    target = None if stop == "initial" else (1.0 + cfg.eps) * reference_length
    return run.Query((sx, sy), (gx, gy), target, (), False, reference_length, setup_time,
                     fallback)  # fmt: skip


def _one_shot(occ: np.ndarray, cfg: PlannerConfig, query: run.Query, seed,
              tested: tuple[float, float]) -> PlanResult:  # fmt: skip
    """plan()'s RRT* run of a query of the common form (:func:`_common`: checked in C, its
    straight segment ``tested`` there, ``(d, seconds)``, not answering it), without a
    :class:`Planner`: the settings kept per config and shape (:func:`.settings.of`), the tree's
    arrays from :data:`run.POOL` and given back. The same run as the Planner's."""
    setup = settings.setup(occ, cfg, uniform_sampler(occ.shape), pooled=True)
    d, spent = tested
    try:
        return run.search(occ, query, planner="rrt_star", setup=setup, rng=rng_state(seed),
                          straight=d >= 0, spent=spent)  # fmt: skip
    finally:
        setup.work.release()


def _seed_ok(seed) -> bool:
    """Whether ``seed`` is an int >= 0 or a tuple (or list) of them."""
    if type(seed) is int:  # the common cases, checked fast: an int, a tuple of ints
        return seed >= 0
    if type(seed) is tuple:  # (~0.1 us; numbers.Integral's isinstance is ~0.3 us a part)
        for s in seed:
            if type(s) is not int or s < 0:
                break  # another kind of part (a bool, a numpy int) or a negative one
        else:
            return True
    parts = seed if isinstance(seed, tuple | list) else (seed,)
    return all(isinstance(s, numbers.Integral) and s >= 0 for s in parts)


def _seed(seed) -> None:
    if not _seed_ok(seed):
        raise ValueError(f"seed must be an int >= 0 or a tuple of them, got {seed!r}")


def _logged(result: PlanResult) -> PlanResult:
    """``result``, its summary logged at DEBUG level."""
    if log.isEnabledFor(logging.DEBUG):
        log.debug("%s", result.summary())
    return result


def _query(occ: np.ndarray, cfg: PlannerConfig, start, goal, stop: str, reference_length,
           seed, milestones, keep_tree: bool, setup_time: float = 0.0, fallback: bool = False,
           known: tuple | None = None) -> tuple[run.Query, tuple[float, float]]:  # fmt: skip
    """The validated query of a solve (arguments and errors: :meth:`Planner.solve`), the
    compiled kernels loaded (:func:`warmup`), and the straight segment's test when
    ``cfg.straight_first`` (:func:`run.straight_test`; made with the endpoints' checks);
    ``known``: :func:`_endpoints`' answer, already made by :func:`_free_segment`."""
    warmup()  # before the straight segment's timed test: its kernel loaded
    start, goal, tested = known or _endpoints(occ, start, goal, cfg.straight_first)
    if stop not in ("initial", "optimal"):
        raise ValueError(f"unknown stop rule {stop!r}; use 'initial' or 'optimal'")
    _seed(seed)
    if reference_length is None and stop == "optimal":
        reference_length = compute_reference(occ, start, goal, cfg.reference)
    if reference_length is not None and not (
        math.isfinite(reference_length) and reference_length >= 0
    ):
        raise ValueError(f"reference_length must be finite and >= 0, got {reference_length}")
    target = None if stop == "initial" else (1.0 + cfg.eps) * reference_length
    bounds = tuple(float(m) for m in milestones) if milestones else ()
    query = run.Query(start, goal, target, bounds, keep_tree, reference_length, setup_time,
                      fallback)  # fmt: skip
    return query, tested


class Planner:
    """One of the paper's RRT* variants set up for one map, as OMPL's ``setup()``: the grid
    validated, the sampler built and the settings checked once; :meth:`solve` answers a
    query (start, goal, stop rule, seed) at a time, reusing the tree's arrays from one query
    to the next (so one solve at a time: not for concurrent use from several threads).

    Args:
        grid: ``(H, W)`` bool/int occupancy, nonzero = obstacle, indexed ``grid[y, x]``; a
            C-contiguous uint8 ``np.ndarray`` is read in place (do not change it while in use).
        planner: ``'rrt_star'`` (uniform), ``'nrrt_star'`` / ``'vnrrt_star'`` (heatmap
            sampler, Algorithm 2) or ``'m_vnrrt_star'`` (heatmap masked below ``config.tau``).
        heatmap: ``(H, W)`` non-negative sampling weights, needed by all but RRT*.
        config: every setting (default :class:`PlannerConfig`).
        sampler: a sampler already built by :func:`make_sampler` for this planner, map and
            config (then no ``heatmap``); checked against them.

    Raises:
        GridError: malformed grid, heatmap of the wrong shape or values.
        ValueError: unknown planner, a sampler that does not match, bad settings.
    """

    def __init__(
        self,
        grid: np.ndarray,
        planner: str = "rrt_star",
        *,
        heatmap: np.ndarray | None = None,
        config: PlannerConfig | None = None,
        sampler: Sampler | None = None,
    ):
        _known(planner)
        self.planner, self.config = planner, _config(config)
        self.occ = _occupancy(grid)
        self.setup_time = 0.0
        if sampler is None:
            t0 = time.perf_counter()
            sampler = make_sampler(planner, self.occ.shape, heatmap, self.config)
            self.setup_time = time.perf_counter() - t0
        elif heatmap is not None:
            raise ValueError("give either a prebuilt sampler or a heatmap, not both")
        else:
            check_sampler(sampler, planner, self.occ.shape, self.config)
        self.sampler = sampler
        self._pooled = False  # plan()'s one-shot planner: its tree comes from run.POOL
        self._setup: run.Setup | None = None  # made by the first tree run (_ready)

    def _ready(self) -> run.Setup:
        """What this planner's tree runs share (:func:`.settings.setup`), made by the
        first."""
        setup = self._setup
        if setup is None:
            setup = self._setup = settings.setup(self.occ, self.config, self.sampler,
                                                 self._pooled)  # fmt: skip
        return setup

    @functools.cached_property
    def gamma(self) -> float:
        """The shrinking-radius constant of this map (:func:`.settings.gamma`)."""
        return settings.gamma(self.occ, self.config)

    def solve(
        self,
        start,
        goal,
        *,
        stop: str = "initial",
        reference_length: float | None = None,
        seed=0,
        milestones: tuple[float, ...] = (),
        keep_tree: bool = False,
    ) -> PlanResult:
        """Plan from ``start`` to ``goal``.

        Args:
            start, goal: continuous points ``(x, y)`` in pixels, in free cells and not
                touching an obstacle or the map border.
            stop: ``'initial'`` (first solution) or ``'optimal'`` (cost <= (1 + eps) x ref).
            reference_length: reference for ``'optimal'``; None computes
                ``config.reference`` (A* length by default) between the cells of the endpoints.
            seed: int >= 0 or tuple of them, seeding the sampler (same seed, same result).
            milestones: extra cost bounds (pixels) whose first-reach time is recorded.
            keep_tree: also return the tree (points and parents) for drawing.

        Returns:
            A :class:`PlanResult`; hitting an iteration or time budget gives ``success=False``.

        Raises:
            GridError: bad start or goal.
            NoPathError: the A* reference is needed and start and goal are not connected.
            ValueError: unknown stop rule, bad reference length or seed (a reference
                length that no path can meet: :func:`.arguments.check_stop_target`).
            TypeError: a reference length that is not a number.
        """
        check_stop_target(stop, reference_length, start, goal, self.config)
        ask = (stop, reference_length, seed, milestones, keep_tree)
        answer = solved(self, start, goal, *ask)  # the common form answered in C, else None
        if answer is not None:
            if type(answer) is not tuple:
                return _logged(answer)
            query = _common(self.config, start, goal, stop, reference_length, answer,
                            self.setup_time, self.sampler.fallback_uniform)  # fmt: skip
            if query is not None:  # checked in C and its segment tested: a tree
                return self._run(query, seed, answer)
        known = None  # (an endpoint touching an obstacle, found in C: _query names it)
        if self.config.straight_first and answer is None:
            answer, known = _free_segment(self.occ, self.config, start, goal, *ask,
                                          self.planner, self.setup_time,
                                          self.sampler.fallback_uniform)  # fmt: skip
            if answer is not None:
                return _logged(answer)
        query, tested = _query(self.occ, self.config, start, goal, *ask, self.setup_time,
                               self.sampler.fallback_uniform, known)  # fmt: skip
        return self._run(query, seed, tested)

    def _run(self, query: run.Query, seed, tested: tuple[float, float]) -> PlanResult:
        """The timed run of a validated query (:mod:`.run`); ``tested``: its straight
        segment's test (:func:`run.straight_test`, made by :func:`_query`)."""
        result = run.straight_answer(self.planner, query, tested)
        if result is None:
            d, spent = tested
            result = run.search(self.occ, query, planner=self.planner, setup=self._ready(),
                                rng=rng_state(seed), straight=d >= 0, spent=spent)  # fmt: skip
        return _logged(result)


def plan(
    grid: np.ndarray,
    start,
    goal,
    planner: str = "rrt_star",
    *,
    heatmap: np.ndarray | None = None,
    config: PlannerConfig | None = None,
    sampler: Sampler | None = None,
    stop: str = "initial",
    reference_length: float | None = None,
    seed=0,
    milestones: tuple[float, ...] = (),
    keep_tree: bool = False,
) -> PlanResult:
    """Plan once from ``start`` to ``goal``: ``Planner(grid, planner, heatmap=heatmap,
    config=config, sampler=sampler).solve(start, goal, stop=stop, ...)``.

    ``grid`` ``(H, W)`` occupancy (nonzero = obstacle, ``grid[y, x]``); ``start``, ``goal``
    continuous ``(x, y)`` pixels; ``planner`` one of :data:`PLANNERS` (all but RRT* sample
    ``heatmap``, or a prebuilt ``sampler``); every setting in ``config`` (default
    :class:`PlannerConfig`; :data:`FASTEST` our fastest); ``stop`` ``'initial'`` or
    ``'optimal'`` (cost <= (1 + eps) x ``reference_length``, None: ``config.reference``
    computed); ``seed`` an int >= 0 or a tuple of them. Arguments and errors: :class:`Planner`
    and :meth:`Planner.solve`. Returns a :class:`PlanResult`. RRT* with ``straight_first``
    answers a free straight segment that meets the stop rule without building the
    :class:`Planner` (the same result, without its setup's microseconds): in one C call
    (:data:`vnrrt.planners.native.planned`) when the arguments have the common form. When
    that form's segment does not answer, the tree's run is made without a :class:`Planner`
    too (:func:`_one_shot`: the settings kept per config and map shape, the tree's arrays
    from a pool; the same result as a Planner's, ``setup_time`` 0: no sampler is built)."""
    check_stop_target(stop, reference_length, start, goal, config)
    answer = planned(grid, start, goal, planner, heatmap, config, sampler, stop,
                     reference_length, seed, milestones, keep_tree)  # fmt: skip
    if answer is not None and type(answer) is not tuple:  # the common form, answered in C
        return _logged(answer)
    if answer is not None:  # the common form, checked in C and its segment tested: a tree
        query = _common(config, start, goal, stop, reference_length, answer)
        if query is not None:  # (None: an endpoint touches an obstacle, named below)
            return _logged(_one_shot(grid, config, query, seed, answer))
    query = None
    if planner == "rrt_star" and heatmap is None and sampler is None:
        config = _config(config)  # uniform sampling: the free segment needs no Planner
        if config.straight_first:
            grid = _occupancy(grid)
            if answer is None:
                answer, known = _free_segment(grid, config, start, goal, stop, reference_length,
                                              seed, milestones, keep_tree)  # fmt: skip
                if answer is not None:
                    return _logged(answer)
            else:  # an endpoint touching an obstacle, found in C: _query names it
                known = None
            query, tested = _query(grid, config, start, goal, stop, reference_length, seed,
                                   milestones, keep_tree, known=known)  # fmt: skip
            answer = run.straight_answer(planner, query, tested)
            if answer is not None:
                return _logged(answer)
    p = Planner(grid, planner, heatmap=heatmap, config=config, sampler=sampler)
    p._pooled = True  # a one-shot planner: its tree's arrays are reused by the next plan()
    try:
        if query is None:
            return p.solve(start, goal, stop=stop, reference_length=reference_length, seed=seed,
                           milestones=milestones, keep_tree=keep_tree)  # fmt: skip
        return p._run(query._replace(setup_time=p.setup_time), seed, tested)
    finally:
        if p._setup is not None:  # a tree was made (not for a free straight segment)
            p._setup.work.release()


@functools.cache
def warmup() -> None:
    """Compile (or load from numba's disk cache) every kernel once per process, so that
    reported timings exclude JIT compilation."""
    occ = np.zeros((8, 8), np.uint8)
    occ[2:6, 4] = 1
    heat = np.ones((8, 8))
    for planner, hm in (("rrt_star", None), ("vnrrt_star", heat)):
        for informed in (False, True):
            cfg = PlannerConfig(max_iterations=200, informed=informed)
            p = Planner(occ, planner, heatmap=hm, config=cfg)
            query = run.Query((1.5, 3.5), (6.5, 3.5), 0.0, (), False, None, 0.0, False)
            p._run(query, 0, run.straight_test(occ, 1.5, 3.5, 6.5, 3.5, True))
    tested = run.straight_test(occ, 1.5, 3.5, 6.5, 3.5, False)
    Planner(occ, config=PlannerConfig(max_iterations=200, gap_share=0.5))._run(query, 0, tested)
    answerer()  # the free segment's C answer bound (its kernel compiled as a C function)
    log.debug("planner kernels compiled")
