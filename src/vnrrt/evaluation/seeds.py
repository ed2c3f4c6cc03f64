"""A comparison whose interval includes the training variance: a bootstrap over network
training seeds, then base maps, instances and trials.

With several trained networks (one per training seed, column ``network_seed`` of a paired
table) the speed-up of a planner over a baseline is the geometric mean over (seed, instance)
of ``median(baseline) / median(planner)`` (iterations counted +1, as in
:func:`vnrrt.evaluation.stats.compare`). Each resample draws

1. the training seeds with replacement (their spread is the training variance),
2. the base maps with replacement, then instances within each drawn map (the same draw for
   every seed: each network runs on the same instances, so seeds and maps are crossed, not
   nested; drawing maps anew per seed would shrink the map variance by the number of seeds),
3. the trials within each (seed, instance), paired (trial t of both configurations).

For a log ratio ``y = mu + a_seed + b_instance + e`` the estimate's variance is
``var(a) / S + var(b) / I + var(e) / (S I)``; the resampling reproduces it (tested against
this formula), where resampling maps alone (``seeds_fixed=True``, one network as today)
leaves out ``var(a) / S``. With one seed the two coincide: the interval of the committed
reports is this one with ``S = 1``, and it states no training variance.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from vnrrt.evaluation.stats import _cluster_weights, _group_medians, _instance_weights, _within


def _codes(values) -> np.ndarray:
    """Dense codes ``0..K-1`` of ``values`` in sorted order."""
    return np.unique(np.asarray(values), return_inverse=True)[1]


def seed_compare(paired: pd.DataFrame, metric: str, *, n_boot: int = 2000, level: float = 0.95,
                 seed: int = 0, seeds_fixed: bool = False) -> dict:  # fmt: skip
    """The speed-up of ``plan`` over ``base`` pooled over training seeds, with its ``level``
    interval (module doc). ``paired``: one row per (network_seed, instance, trial) with
    columns ``network_seed``, ``cluster``, ``instance``, ``trial``, ``base`` and ``plan``
    (the metric's values, > 0; every seed on the same instances). Returns ``speedup``,
    ``ci_low``, ``ci_high``, ``per_seed`` (each seed's own gm), ``seeds``, ``instances``."""
    if metric == "iterations":
        paired = paired.assign(base=paired["base"] + 1.0, plan=paired["plan"] + 1.0)
    df = paired.sort_values(["network_seed", "instance", "trial"], kind="stable")
    s, i = _codes(df["network_seed"]), _codes(df["instance"])
    n_s, n_i = int(s.max()) + 1, int(i.max()) + 1
    pair = s * n_i + i
    if len(np.unique(pair)) != n_s * n_i:
        raise ValueError("every training seed must run on the same instances (a crossed design)")
    rng = np.random.default_rng(seed)
    idx = np.vstack([np.arange(len(df)), _within(pair, n_boot, rng)])
    b, p = df["base"].to_numpy(np.float64), df["plan"].to_numpy(np.float64)
    log_ratio = np.log(_group_medians(b[idx], pair)) - np.log(_group_medians(p[idx], pair))
    seed_of, inst_of = np.arange(n_s * n_i) // n_i, np.arange(n_s * n_i) % n_i
    first = np.unique(i, return_index=True)[1]
    clusters = _codes(df["cluster"].to_numpy()[first])
    w_seed = np.ones((n_boot + 1, n_s))
    if not seeds_fixed:
        w_seed[1:] = _cluster_weights(n_s, n_boot, rng)
    w_inst = np.vstack([np.ones(n_i), _instance_weights(clusters, n_boot, rng)])
    w = w_seed[:, seed_of] * w_inst[:, inst_of]  # (B + 1, S * I)
    gm = np.exp((w * log_ratio).sum(1) / w.sum(1))
    lo, hi = np.quantile(gm[1:], [(1 - level) / 2, (1 + level) / 2])
    per_seed = np.exp(log_ratio[0].reshape(n_s, n_i).mean(1))
    names = np.unique(df["network_seed"].to_numpy())
    return {"speedup": float(gm[0]), "ci_low": float(lo), "ci_high": float(hi),
            "per_seed": {str(k): float(v) for k, v in zip(names, per_seed, strict=True)},
            "seeds": n_s, "instances": n_i}  # fmt: skip
