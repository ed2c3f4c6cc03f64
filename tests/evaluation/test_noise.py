"""The machine's timing noise: RRT* timed twice (the trials stage's schedule and rows), RRT*
read against itself, and the flag of a change within the noise, on synthetic timings whose
noise is known."""

import math

import numpy as np
import pandas as pd
import pytest

from tests.evaluation.test_trials import wall_instance
from vnrrt.evaluation.keys import ConfigKey
from vnrrt.evaluation.noise import band, baseline_record, changes, timing_noise, within
from vnrrt.evaluation.protocol import trial_jobs
from vnrrt.evaluation.table import REPEAT_COLUMNS, SEEDED_COLUMNS
from vnrrt.evaluation.trials import LIBRARY_SETTINGS, interleave, run_jobs
from vnrrt.planners import PlannerConfig


@pytest.mark.parametrize(("n", "k"), [(10, 3), (7, 7), (5, 1), (4, 0), (1, 1)])
def test_every_item_runs_once_and_each_repeat_once_more_spread_in_reverse(n, k):
    order = list(range(n))
    again = order[:k]
    schedule = interleave(order, again)
    assert [i for i, second in schedule if not second] == order
    repeats = [i for i, second in schedule if second]
    assert repeats == list(reversed(again))
    if k > 1:  # spread: the gaps between repeats differ by at most one original item
        where = [p for p, (_, second) in enumerate(schedule) if second]
        gaps = np.diff(where) - 1
        assert gaps.max() - gaps.min() <= 1 and where[-1] == len(schedule) - 1


def test_the_protocol_rrt_star_runs_twice_with_the_same_seeded_results():
    instances = {0: wall_instance(), 1: wall_instance("random", 1)}
    keys = [ConfigKey("rrt_star"), ConfigKey("nrrt_star", source="path"),
            ConfigKey("rrt_star", informed=True)]  # fmt: skip
    counts = {("named", "initial"): 2, ("named", "optimal"): 2, ("random", "optimal"): 1}
    jobs = trial_jobs(["named", "random"], keys, counts)
    once = run_jobs(jobs, instances, 0, 1, PlannerConfig(), LIBRARY_SETTINGS)
    twice = run_jobs(jobs, instances, 0, 1, PlannerConfig(), LIBRARY_SETTINGS, repeat=True)
    pd.testing.assert_frame_equal(once[list(SEEDED_COLUMNS)], twice[list(SEEDED_COLUMNS)])
    protocol = twice["key"] == "rrt_star"
    assert twice.loc[protocol, list(REPEAT_COLUMNS)].notna().all().all()
    assert twice.loc[~protocol, list(REPEAT_COLUMNS)].isna().all().all()
    assert once[list(REPEAT_COLUMNS)].isna().all().all()
    # the second run is another run: its own clock, not a copy of the first's times
    assert (twice.loc[protocol, "time_to_stop_repeat"] != twice.loc[protocol, "time_to_stop"]).any()


def _timed_table(sd: float, instances: int = 60, trials: int = 5, seed: int = 0) -> pd.DataFrame:
    """RRT* rows whose second timing is the first times a lognormal factor (log sd ``sd``)."""
    rng = np.random.default_rng(seed)
    n = instances * trials
    first = rng.lognormal(-5, 1.0, n)
    return pd.DataFrame({
        "instance": np.repeat(np.arange(instances), trials),
        "trial": np.tile(np.arange(trials), instances),
        "cluster": np.repeat(np.arange(instances) // 3, trials), "success": True,
        "stop": "optimal", "map_set": "random", "key": "rrt_star",
        "time_to_stop": first, "time_to_stop_repeat": first * rng.lognormal(0, sd, n),
    })  # fmt: skip


def test_rrt_star_against_itself_reads_one_and_its_band_grows_with_the_noise():
    quiet = timing_noise(_timed_table(0.02), 400, 0.95)["optimal"]["random"]
    loud = timing_noise(_timed_table(0.3), 400, 0.95)["optimal"]["random"]
    for r in (quiet, loud):
        assert r["band_low"] <= 1 <= r["band_high"]
        assert r["band_low"] * r["band_high"] == pytest.approx(1.0)  # symmetric in log
        assert r["band_low"] <= r["ci_low"] and r["ci_high"] <= r["band_high"]
    # the trials' times spread far more than the noise, so both medians pick the same trial:
    # an instance's log ratio has sd ~ sd, their mean over 60 instances sd / sqrt(60); the
    # band reaches the interval's far side, about |mean| + 1.96 of those from 1 (in log)
    for sd, r in ((0.02, quiet), (0.3, loud)):
        half = 1.96 * sd / math.sqrt(60)
        assert 0.7 * half <= math.log(r["band_high"]) <= 2.5 * half
    assert timing_noise(_timed_table(0.1).assign(time_to_stop_repeat=np.nan), 400, 0.95) == {}


def test_band_and_within():
    assert band(0.9, 1.2) == (pytest.approx(1 / 1.2), 1.2)
    assert band(0.95, 1.01) == (0.95, pytest.approx(1 / 0.95))
    assert all(math.isnan(v) for v in band(math.nan, math.nan))
    reading = {"band_low": 0.9, "band_high": 1.1}
    assert within(1.05, reading) and within(0.9, reading) and not within(1.2, reading)
    assert within(1.0, None) is None
    assert within(1.0, {"band_low": math.nan, "band_high": math.nan}) is None


def _claim(text, speedup, iterations, verdict, column="random"):
    return {"text": text, "stop": "optimal", "column": column, "verdict": verdict,
            "time_to_stop": {"speedup": speedup},
            "iterations": {"speedup": iterations}}  # fmt: skip


def test_a_verdict_that_moved_by_less_than_the_noise_is_flagged():
    before = [_claim("a", 1.30, 1.5, "reproduced"), _claim("b", 1.30, 1.5, "reproduced"),
              _claim("c", 2.0, 2.2, "reproduced", "map_9")]  # fmt: skip
    now = [_claim("a", 1.25, 1.5, "no clear effect"), _claim("b", 2.0, 1.9, "larger"),
           _claim("c", 2.1, 2.2, "reproduced", "map_9"), _claim("new", 1.0, 1.0, "x")]  # fmt: skip
    noise = {"optimal": {"random": {"band_low": 0.9, "band_high": 1 / 0.9}}}
    got = {c["text"]: c for c in changes(now, baseline_record(before), noise)}
    assert set(got) == {"a", "b", "c"}  # a claim the baseline lacks is left out
    a, b, c = got["a"], got["b"], got["c"]
    assert a["within_noise"] and a["iterations_same"] and a["ratio"] == pytest.approx(1.25 / 1.3)
    assert (a["verdict_before"], a["verdict_now"]) == ("reproduced", "no clear effect")
    assert b["within_noise"] is False and not b["iterations_same"]
    assert c["within_noise"] is None  # no band measured on map_9
