"""The seed-level bootstrap on synthetic trials with a known between-seed variance: its
variance matches the analytic one, it widens the interval that resampling maps alone gives,
and with one seed it is the committed reports' interval (stats.compare)."""

import numpy as np
import pandas as pd
import pytest

from vnrrt.evaluation.seeds import seed_compare
from vnrrt.evaluation.stats import compare

SEEDS, INSTANCES = 8, 40


def crossed(rng, sd_seed: float, sd_inst: float, sd_noise: float) -> pd.DataFrame:
    """One trial per (seed, instance), each instance its own base map: log(base / plan) =
    0.5 + a_seed + b_instance + e."""
    a = rng.normal(0, sd_seed, SEEDS)
    b = rng.normal(0, sd_inst, INSTANCES)
    rows = []
    for s in range(SEEDS):
        for i in range(INSTANCES):
            y = 0.5 + a[s] + b[i] + rng.normal(0, sd_noise)
            rows.append({"network_seed": s, "cluster": i, "instance": i, "trial": 0,
                         "base": float(np.exp(y)), "plan": 1.0})  # fmt: skip
    return pd.DataFrame(rows)


def _log_var(c: dict, level: float) -> float:
    """The variance of the log speed-up read off a normal interval at ``level``."""
    z = {0.6827: 1.0}[level]
    return ((np.log(c["ci_high"]) - np.log(c["ci_low"])) / (2 * z)) ** 2


def test_the_interval_has_the_analytic_variance_and_widens_with_training_variance():
    rng = np.random.default_rng(0)
    sd_seed, sd_inst, sd_noise = 0.3, 0.3, 0.1
    # E[bootstrap variance] for a crossed two-way resample: each component shrunk by (n-1)/n
    analytic = ((SEEDS - 1) / SEEDS * sd_seed**2 / SEEDS
                + (INSTANCES - 1) / INSTANCES * sd_inst**2 / INSTANCES)  # fmt: skip
    got, fixed = [], []
    for _ in range(60):
        t = crossed(rng, sd_seed, sd_inst, sd_noise)
        got.append(_log_var(seed_compare(t, "time_to_stop", n_boot=2000, level=0.6827), 0.6827))
        f = seed_compare(t, "time_to_stop", n_boot=3000, level=0.6827, seeds_fixed=True)
        fixed.append(_log_var(f, 0.6827))
    noise = sd_noise**2 / (SEEDS * INSTANCES)  # the residual's share: small beside the rest
    assert np.mean(got) == pytest.approx(analytic + noise, rel=0.2)
    assert np.mean(fixed) == pytest.approx(sd_inst**2 / INSTANCES, rel=0.3)  # no var(a) / S
    assert np.mean(got) > 2 * np.mean(fixed)  # the training variance widens the interval


def test_the_point_estimate_and_the_per_seed_readings_equal_numpy():
    t = crossed(np.random.default_rng(1), 0.3, 0.3, 0.1)
    c = seed_compare(t, "time_to_stop", n_boot=200)
    y = np.log(t["base"] / t["plan"])
    assert c["speedup"] == pytest.approx(np.exp(y.mean()), rel=1e-12)
    per_seed = y.groupby(t["network_seed"]).mean()
    assert c["per_seed"] == pytest.approx({str(k): np.exp(v) for k, v in per_seed.items()})
    assert c["seeds"] == SEEDS and c["instances"] == INSTANCES


def test_one_seed_is_the_reports_interval():
    rng = np.random.default_rng(2)
    rows = [{"network_seed": 0, "cluster": i // 2, "instance": i, "trial": k,
             "base": float(rng.lognormal(1, 0.5)), "plan": float(rng.lognormal(0.5, 0.5))}
            for i in range(30) for k in range(3)]  # fmt: skip
    t = pd.DataFrame(rows)
    ours = seed_compare(t, "time_to_stop", n_boot=4000, level=0.9)
    table = t.assign(success=True)
    base = table.rename(columns={"base": "time_to_stop"}).drop(columns="plan")
    plan = table.rename(columns={"plan": "time_to_stop"}).drop(columns="base")
    c = compare(base, plan, "time_to_stop", n_boot=4000, level=0.9)
    assert ours["speedup"] == pytest.approx(c.speedup, rel=1e-12)
    assert (ours["ci_low"], ours["ci_high"]) == pytest.approx((c.ci_low, c.ci_high), rel=0.03)


def test_an_incomplete_design_is_refused():
    t = crossed(np.random.default_rng(3), 0.1, 0.1, 0.1)
    with pytest.raises(ValueError, match="same instances"):
        seed_compare(t.iloc[1:], "time_to_stop")
