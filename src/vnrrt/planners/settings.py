"""The settings of a planner's tree runs, made once before its first run (as OMPL's
``setup()``): the budget, the bucket grid's side, the core's settings
(:class:`vnrrt.planners.core.Params`) and the sampler as the core reads it
(:class:`vnrrt.planners.core.Draws`), from a :class:`vnrrt.planners.PlannerConfig`, a
sampler (:mod:`.samplers`) and the map.

:func:`of` makes those that do not depend on the map's cells, and keeps those of uniform
samplers for the last :data:`KEEP` configs and map shapes (plan()'s one-shot RRT* runs make
them once, not on every call); :func:`setup` adds the map's gamma (:func:`gamma`, its free
area counted) and the tree's workspace (:class:`vnrrt.planners.run.Setup`). Lengths in pixels.
"""

from __future__ import annotations

import math
import threading
from typing import NamedTuple

import numpy as np

from vnrrt.planners import core, run
from vnrrt.planners.config import PlannerConfig
from vnrrt.planners.samplers import Sampler


class Settings(NamedTuple):
    """The settings of a config's tree runs with one sampler on maps of one shape, the map's
    cells apart: the budget, the bucket side (px), the core's settings
    (:class:`vnrrt.planners.core.Params`, a plain tuple) with the query's start and goal and
    the map's gamma left at 0 (:func:`setup` fills the gamma when ``shrinking``), and the
    sampler as the core reads it (``draws``; ``flat_draws`` the same as a plain tuple)."""

    budget: run.Budget
    bucket: float
    params: tuple
    draws: core.Draws
    flat_draws: tuple
    shrinking: bool


KEPT: dict[tuple, tuple] = {}  # of()'s own: (config, sampler, Settings) by their ids
KEPT_LOCK = threading.Lock()  # held while KEPT changes
KEEP = 16  # the (config, uniform sampler, shape) whose Settings are kept
GAMMA = core.Params._fields.index("gamma")


def of(cfg: PlannerConfig, sampler: Sampler, shape: tuple[int, int]) -> Settings:
    """:class:`Settings` of ``cfg`` and ``sampler`` on ``(H, W)`` maps. Those of a uniform
    sampler (plan()'s RRT*, whose sampler is one per shape) are kept for the last
    :data:`KEEP` configs and shapes (a one-shot call makes them once, not each time),
    with the config and the sampler, so that the ids in the key stay theirs."""
    key = (id(cfg), id(sampler), shape)
    kept = KEPT.get(key)
    if kept is not None:
        return kept[2]
    budget = run.Budget(cfg.max_iterations, cfg.max_seconds, cfg.trace_capacity)
    bucket = max(min(cfg.eta, max(shape)) / 2, 1.0)  # an unlimited step: the map
    cdf = sampler.cdf if sampler.cdf.size else np.zeros(1)
    share = float(cfg.gap_share)  # the gap cells pending (-1) when used: found in the run
    draws = core.Draws(float(sampler.draw_mix), cdf, max(sampler.last, 0), share,
                       int(cfg.gap_width), int(cfg.gap_after), core.NO_CELLS,
                       -1 if share > 0 else 0)  # fmt: skip
    params = core.Params(
        eta=float(cfg.eta),
        gamma=0.0,  # the map's, when shrinking: setup()
        radius=float(cfg.fixed_radius),
        goal_radius=float(cfg.eta if cfg.goal_radius is None else cfg.goal_radius),
        sx=0.0,  # the query's start and goal: run.query_params
        sy=0.0,
        gx=0.0,
        gy=0.0,
        min_spacing=float(cfg.min_spacing),
        bucket=bucket,
        informed=bool(cfg.informed),
        refine=float(cfg.refine),
        pull_parents=bool(cfg.pull_parents),
        refine_branches=float(cfg.refine_branches),
    )
    shrinking = cfg.radius_mode == "shrinking"
    made = Settings(budget, bucket, tuple(params), draws, tuple(draws), shrinking)
    if sampler.kind == "uniform":
        with KEPT_LOCK:
            while len(KEPT) >= KEEP:
                del KEPT[next(iter(KEPT))]  # the oldest
            KEPT[key] = (cfg, sampler, made)
    return made


def setup(occ: np.ndarray, cfg: PlannerConfig, sampler: Sampler, pooled: bool) -> run.Setup:
    """What the tree runs of ``cfg`` with ``sampler`` on ``occ`` share (:class:`run.Setup`):
    the tree's arrays (taken from :data:`run.POOL` when ``pooled``) and the core's settings,
    the map's gamma (:func:`gamma`) in them when the radius shrinks."""
    made = of(cfg, sampler, occ.shape)
    params = made.params
    if made.shrinking:
        params = (*params[:GAMMA], gamma(occ, cfg), *params[GAMMA + 1 :])
    work = run.Workspace(occ.shape, made.bucket, made.budget, pooled=pooled)
    return run.Setup(work, params, made.draws, made.flat_draws)


def gamma(occ: np.ndarray, cfg: PlannerConfig) -> float:
    """The shrinking-radius constant: ``cfg.gamma_factor`` x (``cfg.gamma``, or the RRT*
    bound ``2 (1 + 1/d)^(1/d) (free area / unit-ball area)^(1/d)``, d = 2, of the map
    ``occ``, its free area in cells)."""
    factor = float(cfg.gamma_factor)
    if cfg.gamma is not None:
        return factor * float(cfg.gamma)
    free = occ.size - np.count_nonzero(occ)
    return factor * 2.0 * math.sqrt(1.5) * math.sqrt(free / math.pi)
