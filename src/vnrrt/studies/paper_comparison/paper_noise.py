"""The paper's own uncertainty: an interval for each quoted improvement from the paper's
published means, standard deviations and trial counts.

The paper quotes improvements as ``mean(baseline) / mean(planner) - 1`` (e.g. 19.38 / 3.71 -
1 = 422.37 %). Its planners were run separately (not paired), so the two means are
independent. The interval is the **delta method on the log of a ratio of independent means**:

    log R = log m_b - log m_p,   Var(log R) ~ s_b^2 / (n_b m_b^2) + s_p^2 / (n_p m_p^2),

``R`` in ``exp(log R +- z se)``, the improvement ``R - 1``; ``z`` the normal quantile of the
confidence level. :func:`simulated_interval` gives the same interval by a parametric
simulation (normal sampling distributions of the two means), an independent check (tested).
A claim is *significant in the paper's own data* when its interval excludes 0.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass

import numpy as np
from scipy.stats import norm


@dataclass(frozen=True)
class PaperInterval:
    """A quoted improvement (``ratio - 1``) and its interval from the paper's own data."""

    improvement: float
    low: float
    high: float
    level: float
    n_baseline: int
    n_planner: int

    @property
    def significant(self) -> bool:
        """The interval excludes zero (an effect in the paper's own data)."""
        return self.low > 0 or self.high < 0

    def as_dict(self) -> dict:
        return {**asdict(self), "significant": self.significant}


def ratio_interval(baseline: tuple[float, float, int], planner: tuple[float, float, int],
                   level: float, rho: float = 0.0) -> PaperInterval:  # fmt: skip
    """The delta-method interval (module doc) of ``mean_b / mean_p - 1``; ``baseline`` and
    ``planner`` are ``(mean, sd, n)``. ``rho`` > 0: the sensitivity to pairing, as if the
    two planners' times on the same map were correlated ``rho`` (the covariance term
    ``- 2 rho sqrt(a b)`` of ``Var(log R) = a + b``, ``a = s_b^2 / (n_b m_b^2)``, ``b`` the
    planner's); 0, the paper's unpaired reading."""
    (mb, sb, nb), (mp, sp, np_) = baseline, planner
    if min(mb, mp) <= 0 or min(nb, np_) < 2 or min(sb, sp) < 0 or not 0 <= rho < 1:
        raise ValueError(f"need positive means, n >= 2, sd >= 0, 0 <= rho < 1: {baseline}, "
                         f"{planner}, rho={rho}")  # fmt: skip
    log_r = math.log(mb) - math.log(mp)
    a, b = sb**2 / (nb * mb**2), sp**2 / (np_ * mp**2)
    se = math.sqrt(a + b - 2 * rho * math.sqrt(a * b))
    z = float(norm.ppf(0.5 + level / 2))
    return PaperInterval(
        math.exp(log_r) - 1,
        math.exp(log_r - z * se) - 1,
        math.exp(log_r + z * se) - 1,
        level,
        int(nb),
        int(np_),
    )


def simulated_interval(
    baseline: tuple[float, float, int],
    planner: tuple[float, float, int],
    level: float,
    draws: int = 200_000,
    seed: int = 0,
) -> tuple[float, float]:
    """The same interval by simulation: the two means drawn from their normal sampling
    distributions (``N(m, s^2 / n)``), the central ``level`` share of ``m_b / m_p - 1``."""
    rng = np.random.default_rng(seed)
    (mb, sb, nb), (mp, sp, np_) = baseline, planner
    b = rng.normal(mb, sb / math.sqrt(nb), draws)
    p = rng.normal(mp, sp / math.sqrt(np_), draws)
    keep = (b > 0) & (p > 0)  # a mean time cannot be negative
    lo, hi = np.quantile(b[keep] / p[keep] - 1, [0.5 - level / 2, 0.5 + level / 2])
    return float(lo), float(hi)


def paper_cell(paper: dict, table: str, key: str, column: str) -> tuple[float, float, int]:
    """``(mean, sd, n)`` of configuration ``key`` in column ``column`` of the paper's table
    ``table`` (``n``: the table's trials for that column, ``trials`` in ``tables.yaml``)."""
    spec = paper["tables"][table]
    col = paper["columns"].index(column)
    mean, sd = spec["rows"][key][col]
    n = spec["trials"][column] if isinstance(spec["trials"], dict) else spec["trials"][col]
    return float(mean), float(sd), int(n)


def claim_interval(paper: dict, claim: dict, level: float, rho: float = 0.0) -> PaperInterval:
    """The paper's interval of one quoted claim (``tables.yaml``'s ``claims`` entry), its
    planners correlated ``rho`` (:func:`ratio_interval`; 0: unpaired, the paper's design)."""
    table, column = claim["table"], claim["column"]
    base = paper_cell(paper, table, claim["baseline"], column)
    plan = paper_cell(paper, table, claim["planner"], column)
    return ratio_interval(base, plan, level, rho)
