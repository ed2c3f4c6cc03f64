"""The entry points: :class:`Planner` (set up once per map, solved many times) and
:func:`plan` (one call: a :class:`Planner` built and solved once).

Coordinates follow :mod:`vnrrt.grid`: ``grid`` is ``(H, W)`` indexed ``grid[y, x]``
(nonzero = obstacle), start and goal are continuous ``(x, y)`` pixel points (cell centres
``(x + 0.5, y + 0.5)`` for dataset instances); lengths in pixels, times in seconds. Every
setting comes from one :class:`PlannerConfig` (the M-VNRRT* threshold ``tau`` included).

:meth:`Planner.solve` checks the query, then makes one timed run (:func:`.run.run`: the
straight segment when ``straight_first``, else the compiled RRT* core). Timings cover that
run; building the sampler from a heatmap (per map, once; reported as ``setup_time``),
allocating the tree's arrays (per planner, reused), seeding, JIT compilation (once per
process, :func:`warmup`) and the reference-length computation (an oracle, not part of
planning) are outside them.
"""

from __future__ import annotations

import functools
import logging
import math
import numbers
import time

import numpy as np

from vnrrt.grid import GridError, as_occupancy, as_point
from vnrrt.planners import run
from vnrrt.planners.arguments import check_stop_target
from vnrrt.planners.collision import segment_free
from vnrrt.planners.config import PLANNERS, USER, PlannerConfig
from vnrrt.planners.reference import reference_length as compute_reference
from vnrrt.planners.result import PlanResult
from vnrrt.planners.samplers import Sampler, heatmap_sampler, uniform_sampler

log = logging.getLogger(__name__)

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
    """``config`` validated; None gives :data:`~vnrrt.planners.config.USER`."""
    if config is None:
        return USER
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
    if type(grid) is np.ndarray and grid.dtype == np.uint8 and grid.ndim == 2:  # noqa: SIM102
        if min(grid.shape) >= 2 and grid.flags.c_contiguous:  # (shape read on 2-D arrays only)
            return grid
    return as_occupancy(grid)


def _endpoint(occ: np.ndarray, point, name: str) -> tuple[float, float]:
    """``point`` as floats ``(x, y)``: finite, in a free cell, touching no obstacle or border
    (one compiled test; a point that fails it is named by :func:`as_point` or here)."""
    try:
        x, y = point
        x, y = float(x), float(y)
    except (TypeError, ValueError):
        x = y = math.nan
    if math.isfinite(x) and math.isfinite(y) and segment_free(occ, x, y, x, y):
        return x, y
    x, y = as_point(occ, point, name)  # names a malformed point, one outside, one in an obstacle
    raise GridError(f"{name} {(x, y)} touches an obstacle cell or the map border")


def _check_seed(seed) -> None:
    """Raise ``ValueError`` unless ``seed`` is an int >= 0 or a tuple (or list) of them."""
    parts = seed if isinstance(seed, tuple | list) else (seed,)
    if not all(isinstance(s, numbers.Integral) and s >= 0 for s in parts):
        raise ValueError(f"seed must be an int >= 0 or a tuple of them, got {seed!r}")


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
        config: every setting. Default :data:`~vnrrt.planners.USER`
            (``conf/planner/user.yaml``: our fastest settings, budgets scaled with the map's
            free cells F: ``max(200000, ceil(50 F))`` iterations, ``max(30, 0.0002 F)``
            seconds); the paper's protocol is :meth:`PlannerConfig.paper`.
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
        self.setup = run.Setup(self.occ, self.config, sampler)

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
        warmup()  # before the timed run: the kernels compiled (once per process)
        query = self._query(start, goal, stop=stop, reference_length=reference_length,
                            seed=seed, milestones=milestones, keep_tree=keep_tree)  # fmt: skip
        result = run.run(self.occ, query, planner=self.planner, setup=self.setup, seed=seed)
        if log.isEnabledFor(logging.DEBUG):
            log.debug("%s", result.summary())
        return result

    def _query(self, start, goal, *, stop, reference_length, seed, milestones, keep_tree
               ) -> run.Query:  # fmt: skip
        """The checked query of :meth:`solve` (arguments and errors there), its reference
        computed when ``stop`` is ``'optimal'`` and none is given."""
        check_stop_target(stop, reference_length, start, goal, self.config)
        start, goal = _endpoint(self.occ, start, "start"), _endpoint(self.occ, goal, "goal")
        if stop not in ("initial", "optimal"):
            raise ValueError(f"unknown stop rule {stop!r}; use 'initial' or 'optimal'")
        _check_seed(seed)
        if reference_length is None and stop == "optimal":
            reference_length = compute_reference(self.occ, start, goal, self.config.reference)
        target = None if stop == "initial" else (1.0 + self.config.eps) * reference_length
        bounds = tuple(float(m) for m in milestones)
        return run.Query(start, goal, target, bounds, keep_tree, reference_length,
                         self.setup_time, self.sampler.fallback_uniform)  # fmt: skip


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
    :data:`USER`, ``conf/planner/user.yaml``: our fastest settings with budgets scaled with
    the map's free area, see :class:`Planner`; :meth:`PlannerConfig.paper` the paper's
    protocol); ``stop`` ``'initial'`` or
    ``'optimal'`` (cost <= (1 + eps) x ``reference_length``, None: ``config.reference``
    computed); ``seed`` an int >= 0 or a tuple of them. Arguments and errors: :class:`Planner`
    and :meth:`Planner.solve`. Returns a :class:`PlanResult`."""
    p = Planner(grid, planner, heatmap=heatmap, config=config, sampler=sampler)
    return p.solve(start, goal, stop=stop, reference_length=reference_length, seed=seed,
                   milestones=milestones, keep_tree=keep_tree)  # fmt: skip


@functools.cache
def warmup() -> None:
    """Compile (or load from numba's disk cache) every kernel once per process, so that
    reported timings exclude JIT compilation."""
    occ = np.zeros((8, 8), np.uint8)
    occ[2:6, 4] = 1
    heat = np.ones((8, 8))
    query = run.Query((1.5, 3.5), (6.5, 3.5), 0.0, (), False, None, 0.0, False)
    for planner, hm in (("rrt_star", None), ("vnrrt_star", heat)):
        for informed in (False, True):
            p = Planner(occ, planner, heatmap=hm,
                        config=PlannerConfig(max_iterations=200, informed=informed))  # fmt: skip
            run.run(occ, query, planner=planner, setup=p.setup, seed=0)
    p = Planner(occ, config=PlannerConfig(max_iterations=200, gap_share=0.5, straight_first=True))
    run.run(occ, query, planner="rrt_star", setup=p.setup, seed=0)
    log.debug("planner kernels compiled")
