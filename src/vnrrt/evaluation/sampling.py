"""The sampler of one evaluated configuration, with the one obstacle rule applied in one place.

A sampler draws from its heatmap with probability ``mix`` (``planner.mix`` or the key's
``~mix``), else a uniform point. The obstacle rule (:func:`vnrrt.evaluation.sources.allowed_cells`)
decides where both may land:

* **every cell** (the default, the paper's ``UniformSample``): the heatmap as it is (a
  network's prediction, an oracle's blurred target), uniform points over the whole map;
* **free cells only** (``eval.zero_obstacles``, or a key's ``+free`` flipping it): the heatmap is
  zero on obstacle cells (:func:`vnrrt.evaluation.sources.source_heatmap`), and the uniform
  part draws a uniform free cell. That is the mixture ``mix H / sum(H) + (1 - mix) F / sum(F)``
  (``F`` the free cells) drawn as one heatmap with probability 1: the same distribution, one
  sampler of the planners' own code. RRT* then samples ``F`` alone.

Sampled points lie uniformly inside the chosen pixel either way.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from vnrrt.evaluation.keys import ConfigKey
from vnrrt.planners import PlannerConfig, Sampler, heatmap_sampler, make_sampler


def free_rule(key: ConfigKey, default: bool) -> bool:
    """Whether ``key`` samples free cells only: the default rule, flipped by ``+free``."""
    return default != key.free


def build_sampler(
    key: ConfigKey,
    heatmap: np.ndarray | None,
    allowed: np.ndarray,
    config: PlannerConfig,
    free: bool,
) -> tuple[Sampler, PlannerConfig, bool]:
    """``(sampler, settings, fallback)``: the sampler of ``key`` on a map whose allowed cells
    are ``allowed`` ``(H, W)`` bool, the settings ``plan`` must run it with, and whether its
    heatmap had no weight left (M-VNRRT*'s mask: it samples uniformly then); ``heatmap``
    (already zero outside ``allowed``) is the source's, None for RRT*; ``free``:
    :func:`free_rule`."""
    if key.mix is not None:
        config = config.replace(mix=float(key.mix))
    shape = allowed.shape
    if not free:
        s = make_sampler(key.planner, shape, heatmap, config=config)
        return s, config, s.fallback_uniform
    uniform = allowed / allowed.sum()
    if key.planner == "rrt_star":
        s = heatmap_sampler(uniform, shape, mix=1.0)
        return dataclasses.replace(s, kind="uniform"), config, False
    masked = make_sampler(key.planner, shape, heatmap, config=config)
    weights = np.asarray(heatmap, np.float64)
    if key.tau is not None:
        weights = np.where(weights >= key.tau, weights, 0.0)
    total = weights.sum()
    mixture = uniform if total <= 0 else config.mix * weights / total + (1 - config.mix) * uniform
    s = heatmap_sampler(mixture, shape, mix=1.0)
    s = dataclasses.replace(s, kind=masked.kind, tau=masked.tau)
    return s, config.replace(mix=1.0), masked.fallback_uniform
