"""The entry points: :class:`Planner` (set up once per map, solved many times) and
:func:`plan` (one call: a :class:`Planner` built and solved once).

Coordinates follow :mod:`vnrrt.grid`: ``grid`` is ``(H, W)`` indexed ``grid[y, x]``
(nonzero = obstacle), start and goal are continuous ``(x, y)`` pixel points (cell centres
``(x + 0.5, y + 0.5)`` for dataset instances); lengths in pixels, times in seconds.

:meth:`Planner.solve` checks the query (:mod:`.arguments`) and makes one timed run
(:func:`.run.run`). Outside its times: building the sampler from a heatmap (per map, once;
``setup_time``), allocating the tree's arrays (per planner, reused), seeding, JIT
compilation (once per process, :func:`warmup`) and the reference length (an oracle).
"""

from __future__ import annotations

import functools
import logging
import time

import numpy as np

from vnrrt.planners import arguments, run
from vnrrt.planners.config import PlannerConfig
from vnrrt.planners.reference import reference_length as compute_reference
from vnrrt.planners.result import PlanResult
from vnrrt.planners.samplers import Sampler, heatmap_sampler, uniform_sampler

log = logging.getLogger(__name__)


def make_sampler(
    planner: str, shape: tuple[int, int], heatmap=None, *, config: PlannerConfig | None = None
) -> Sampler:
    """The sampler of ``planner`` for an ``(H, W)`` map (see :mod:`.samplers`), built with
    ``config.mix`` and, for M-VNRRT*, ``config.tau``."""
    arguments.check_planner(planner)
    cfg = arguments.checked_config(config)
    if planner == "rrt_star":
        if heatmap is not None:
            raise ValueError("rrt_star samples uniformly and takes no heatmap")
        return uniform_sampler(shape)
    if heatmap is None:
        raise ValueError(f"{planner} needs a heatmap of shape {tuple(shape)}")
    tau = cfg.tau if planner == "m_vnrrt_star" else None
    return heatmap_sampler(heatmap, shape, mix=cfg.mix, tau=tau)


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
        arguments.check_planner(planner)
        self.planner, self.config = planner, arguments.checked_config(config)
        self.occ = arguments.occupancy(grid)
        self.setup_time = 0.0
        if sampler is None:
            t0 = time.perf_counter()
            sampler = make_sampler(planner, self.occ.shape, heatmap, config=self.config)
            self.setup_time = time.perf_counter() - t0
        elif heatmap is not None:
            raise ValueError("give either a prebuilt sampler or a heatmap, not both")
        else:
            arguments.check_sampler(sampler, planner, self.occ.shape, self.config)
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
        start = arguments.endpoint(self.occ, start, "start")
        goal = arguments.endpoint(self.occ, goal, "goal")
        if stop != "initial" and stop != "optimal":
            raise ValueError(f"unknown stop rule {stop!r}; use 'initial' or 'optimal'")
        arguments.check_stop_target(stop, reference_length, start, goal, self.config)
        arguments.check_seed(seed)
        if stop == "initial":
            target = None
        else:
            if reference_length is None:
                reference_length = compute_reference(self.occ, start, goal, self.config.reference)
            target = (1.0 + self.config.eps) * reference_length
        bounds = tuple(map(float, milestones)) if milestones else ()
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
    config=config, sampler=sampler).solve(start, goal, stop=stop, ...)``; arguments, errors
    and defaults there (:class:`Planner`, :meth:`Planner.solve`)."""
    p = Planner(grid, planner, heatmap=heatmap, config=config, sampler=sampler)
    return p.solve(start, goal, stop=stop, reference_length=reference_length, seed=seed,
                   milestones=milestones, keep_tree=keep_tree)  # fmt: skip


@functools.cache
def warmup() -> None:
    """Compile (or load from numba's disk cache) every kernel once per process, so that
    reported timings exclude JIT compilation."""
    occ = np.zeros((8, 8), np.uint8)
    occ[2:6, 4] = 1  # a wall: the straight segment tested and blocked, the tree grown
    cfg = PlannerConfig(max_iterations=200, informed=True, gap_share=0.5, straight_first=True)
    p = Planner(occ, "vnrrt_star", heatmap=np.ones((8, 8)), config=cfg)
    query = run.Query((1.5, 3.5), (6.5, 3.5), 0.0, (), False, None, 0.0, False)
    run.run(occ, query, planner="vnrrt_star", setup=p.setup, seed=0)
    log.debug("planner kernels compiled")
