"""The machine's timing noise, and whether a time reading moved by more than it.

The trials stage runs the protocol's RRT* twice (``eval.timing_noise``; the second runs
spread over the stage, :func:`vnrrt.evaluation.trials.interleave`): the same seeds, so the
same iterations and costs, timed twice (``time_to_stop`` and ``time_to_stop_repeat``). RRT*
read against itself (:func:`vnrrt.evaluation.stats.compare`, paired and clustered, as every
claim is read) differs from 1 only by the machine's timing noise.

*The noise band* of a (stop rule, map set) is that reading's interval, made symmetric on the
log scale: ``[min(lo, 1/hi), max(hi, 1/lo)]``. It is how far a time speed-up on these
instances moves when nothing but the timing changes; a claim's time reading whose ratio to
the same claim's reading in a baseline run (the user's default run) lies inside the band
changed *within timing noise* (:func:`changes`). The band is measured on RRT* and applied to
every configuration: a planner with a different time profile may be noisier or quieter.
"""

from __future__ import annotations

import math

import pandas as pd

from vnrrt.evaluation.stats import compare


def timing_noise(table: pd.DataFrame, n_boot: int, level: float) -> dict:
    """``{stop: {map_set: reading}}`` of every (stop rule, map set) whose rows were timed
    twice; a reading is :meth:`Comparison.as_dict` of the first timing against the second
    (``speedup`` near 1) with the band (``band_low``, ``band_high``; module doc), at
    ``level`` from ``n_boot`` resamples. ``{}`` where nothing was timed twice."""
    again = table[table["time_to_stop_repeat"].notna()]
    out: dict = {}
    for (stop, map_set), first in again.groupby(["stop", "map_set"], sort=False):
        second = first.assign(time_to_stop=first["time_to_stop_repeat"])
        reading = compare(second, first, "time_to_stop", n_boot=n_boot, level=level).as_dict()
        reading["band_low"], reading["band_high"] = band(reading["ci_low"], reading["ci_high"])
        out.setdefault(stop, {})[map_set] = reading
    return out


def band(low: float, high: float) -> tuple[float, float]:
    """The noise band of an interval ``[low, high]`` of a ratio (module doc)."""
    if not (math.isfinite(low) and math.isfinite(high)) or low <= 0:
        return math.nan, math.nan
    return min(low, 1 / high), max(high, 1 / low)


def within(ratio: float, reading: dict | None) -> bool | None:
    """Whether a change ``ratio`` (now / baseline speed-up) lies inside ``reading``'s band;
    None where there is no band (not measured, or too few trials for an interval)."""
    if reading is None or not math.isfinite(reading["band_low"]):
        return None
    return reading["band_low"] <= ratio <= reading["band_high"]


def changes(rows: list[dict], baseline: dict, noise: dict) -> list[dict]:
    """Each claim of ``rows`` (the summary's claim rows: ``stop`` and ``column`` name its
    stop rule and map set) against its reading in ``baseline`` (:func:`baseline_record`):
    ``{text, before, now, ratio, within_noise, iterations_same, verdict_before,
    verdict_now}``; ``noise`` is :func:`timing_noise`'s result. Claims without data on
    either side are left out."""
    out = []
    for row in rows:
        was, t = baseline.get(row["text"]), row["time_to_stop"]
        if was is None or t is None:
            continue
        ratio = t["speedup"] / was["speedup"]
        reading = noise.get(row["stop"], {}).get(row["column"])
        it = row["iterations"]
        out.append({
            "text": row["text"],
            "before": was["speedup"],
            "now": t["speedup"],
            "ratio": ratio,
            "within_noise": within(ratio, reading),
            "iterations_same": it is not None and it["speedup"] == was["iterations"],
            "verdict_before": was["verdict"],
            "verdict_now": row["verdict"],
        })  # fmt: skip
    return out


def baseline_record(rows: list[dict]) -> dict:
    """What :func:`changes` needs of a run's claims (the summary's claim rows): ``{text:
    {speedup, iterations, verdict}}`` (time speed-up, iteration speed-up, verdict)."""
    return {
        r["text"]: {
            "speedup": r["time_to_stop"]["speedup"],
            "iterations": r["iterations"]["speedup"] if r["iterations"] else None,
            "verdict": r["verdict"],
        }
        for r in rows
        if r["time_to_stop"] is not None
    }
