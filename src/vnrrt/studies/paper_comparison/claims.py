"""The paper's quoted claims judged as a referee would (stage ``evaluate``).

* **One verdict per claim.** A claim is read on time (its own metric, the verdict) and on
  iterations (a second reading, shown beside it), both paired and clustered
  (:func:`vnrrt.evaluation.stats.compare`), at the family-wise level over the claims tested
  (Bonferroni: ``1 - (1 - level) / claims``), with enough bootstrap resamples that each tail
  of the corrected interval holds ``stats.tail_draws`` draws.
* **The paper's own noise.** Each claim's interval from the paper's means, sds and trial
  counts (:mod:`.paper_noise`, its planners unpaired as the paper ran them; its sensitivity
  to pairing at the correlations ``stats.pairing``), at the same corrected level. Our ratio
  of means (the paper's estimand) is *compatible with the paper's data* when the interval of
  the difference (:mod:`.readings`) contains no difference, and *contradicts* it otherwise.
* **Four readings, one verdict.** Time and iterations, each as the paper's ratio of means
  and as our geometric mean of per-instance ratios of medians (:mod:`.readings`); the
  verdict is the time reading's (ours), with a robustness column.
* **Turning-point strata.** With the instances' strata (:mod:`vnrrt.evaluation.strata`),
  every claim again per stratum.
* **What a masked claim tests.** Where M-VNRRT*'s sampler puts its mass after the mask
  (start/goal disks, interior vertices, the rest of the path) and how often it falls back to
  uniform sampling (:func:`mask_shares`); a claim whose masked sampler is mostly on the
  start/goal disks or mostly falls back is *not testable with this network*
  (:func:`testability`).
"""

from __future__ import annotations

import math

import pandas as pd

from vnrrt.evaluation.keys import ConfigKey
from vnrrt.evaluation.stats import bonferroni_level, compare, verdict
from vnrrt.evaluation.strata import stratum_names
from vnrrt.studies.paper_comparison.paper_noise import claim_interval
from vnrrt.studies.paper_comparison.readings import (
    COMPATIBLE,
    CONTRADICTS,
    ITERATIONS,
    PAPERS,
    PRIMARY,
    compatibility,
    difference,
    read_claim,
    robustness,
)

SHARES = ("mass_endpoints", "mass_interior", "mass_path")
__all__ = ["COMPATIBLE", "CONTRADICTS", "claims", "mask_shares", "testability"]


def improvement(c: dict, lo: str = "ci_low", hi: str = "ci_high", mid: str = "speedup") -> str:
    """A reading's improvement (ratio - 1) with its interval, as the report and the
    dashboard show it: ``+12.3% [+1.0%, +25.0%]``."""
    return f"{c[mid] - 1:+.1%} [{c[lo] - 1:+.1%}, {c[hi] - 1:+.1%}]"


def verdict_text(row: dict) -> str:
    """A claim's verdict in the report's words (the dashboard's too): with the iterations'
    verdict where it differs from the time reading's (``no clear effect; on iterations:
    reproduced``), and ``different map: not comparable (...)`` off the comparable column."""
    text, it = row["verdict"], row.get("iterations")
    if row.get("time_to_stop") and it and it["verdict"] != text:
        text = f"{text}; on iterations: {it['verdict']}"
    return on_its_map(text, row["comparable"])


def on_its_map(verdict: str, comparable: bool) -> str:
    """``verdict`` as said of a claim on the paper's comparable map set, or wrapped as
    ``different map: not comparable (...)`` off it."""
    return verdict if comparable else f"different map: not comparable ({verdict})"


def mask_shares(table: pd.DataFrame) -> dict:
    """``{stop: {key: {map_set: {mass_endpoints, mass_interior, mass_path, fallback_rate,
    instances}}}}`` for every configuration with a heatmap: the shares averaged over
    instances (one value per instance), the fallback rate over trials."""
    out: dict = {}
    heat = table[table["source"] != ""]
    for (stop, key, map_set), sub in heat.groupby(["stop", "key", "map_set"], sort=False):
        per_instance = sub.groupby("instance")[list(SHARES)].first()
        cell = {s: _mean(per_instance[s]) for s in SHARES}
        cell["fallback_rate"] = float(sub["fallback_uniform"].mean())
        cell["instances"] = int(len(per_instance))
        out.setdefault(stop, {}).setdefault(key, {})[map_set] = cell
    return out


def _mean(values: pd.Series) -> float | None:
    v = values.dropna()
    return float(v.mean()) if len(v) else None


def testability(cell: dict | None, max_endpoints: float, max_fallback: float) -> dict:
    """Whether a masked claim tests the mask (``cell``: its :func:`mask_shares` entry): not
    when more than ``max_endpoints`` of its sampler's mass lies on the start/goal disks or
    it falls back to uniform in more than ``max_fallback`` of the trials."""
    if cell is None:
        return {"testable": True, "why": ""}
    why = []
    ends = cell.get("mass_endpoints")
    if ends is not None and ends > max_endpoints:
        why.append(f"{ends:.1%} of its sampler's mass is on the start/goal disks")
    if cell["fallback_rate"] > max_fallback:
        why.append(f"it falls back to uniform sampling in {cell['fallback_rate']:.0%} of trials")
    return {"testable": not why, "why": "; ".join(why)}


def testability_rule(st) -> str:
    """When a masked claim is not testable with a network (:func:`testability` with the
    ``stats`` section ``st``'s thresholds), in the reports' words."""
    return (f"more than {st.untestable_endpoint_share:.0%} of its sampler's mass lies on the "
            f"start/goal disks, or it falls back to uniform sampling in more than "
            f"{st.untestable_fallback:.0%} of its trials")  # fmt: skip


def _pair(table: pd.DataFrame, paper: dict, claim: dict):
    """(baseline rows, planner rows) of a claim's table column; None if either is missing."""
    stop = paper["tables"][claim["table"]]["stop"]
    sel = table[(table["stop"] == stop) & (table["map_set"] == claim["column"])]
    base, plan = sel[sel["key"] == claim["baseline"]], sel[sel["key"] == claim["planner"]]
    return None if base.empty or plan.empty else (base, plan)


def claim_boot(n_boot: int, tail_draws: int, level: float) -> int:
    """Resamples for intervals at ``level``: at least ``n_boot``, and enough that each tail
    holds ``tail_draws`` draws."""
    return max(n_boot, math.ceil(tail_draws / ((1 - level) / 2) - 1e-6))  # float noise


def _readings(pair, metrics: list[str], n_boot: int, level: float) -> dict:
    """``{metric: Comparison dict}`` of a claim's (baseline, planner) rows; None: no data."""
    if pair is None:
        return {m: None for m in metrics}
    return {m: compare(*pair, m, n_boot=n_boot, level=level).as_dict() for m in metrics}


def _judged(readings: dict, claim: dict, iv: dict, level: float) -> dict:
    """The readings (:func:`_readings`) with each reading's verdict (:mod:`.readings`), the
    four-way table, its robustness and the claim's verdict (the primary reading's)."""
    if readings["time_to_stop"] is None:
        return {**readings, "verdict": "no data", "readings": {}, "robustness": "no data"}
    read = read_claim(readings, claim["quoted"], iv, level)
    readings["time_to_stop"]["verdict"] = read[PRIMARY]["verdict"]
    readings["iterations"]["verdict"] = read[ITERATIONS]["verdict"]
    if readings.get("time_total"):
        c = readings["time_total"]
        c["verdict"] = verdict(claim["quoted"], c["ci_low"] - 1, c["ci_high"] - 1)
    return {**readings, "verdict": read[PRIMARY]["verdict"], "readings": read,
            "robustness": robustness(read)}  # fmt: skip


def _per_stratum(pair, strata: dict, names: list[str], claim: dict, iv: dict, n_boot: int,
                 level: float) -> dict:  # fmt: skip
    """``{stratum: {instances, readings...}}`` of a claim's rows (:func:`_judged` per stratum
    of ``strata``: instance -> stratum name); a stratum without instances: ``instances`` 0."""
    out = {}
    for name in names:
        if pair is None:
            out[name] = {"instances": 0}
            continue
        keep = [t[t["instance"].map(strata).eq(name)] for t in pair]
        n = int(keep[0]["instance"].nunique())
        sub = _readings(keep if n else None, ["time_to_stop", "iterations"], n_boot, level)
        out[name] = {"instances": n, **(_judged(sub, claim, iv, level) if n else {})}
    return out


def _paper_pairing(paper: dict, claim: dict, level: float, rhos, ours) -> dict:
    """``{rho: {low, high, paper_data}}``: the paper's interval had its planners been paired
    with correlation ``rho``, and our ratio of means (``ours``: Comparison dict) judged
    against it by the difference interval."""
    out = {}
    for rho in rhos:
        iv = claim_interval(paper, claim, level, rho).as_dict()
        data = None
        if ours is not None:
            est = (ours["ratio_of_means"], ours["rom_ci_low"], ours["rom_ci_high"])
            data = compatibility(difference(est, iv, level))
        out[str(rho)] = {"low": iv["low"], "high": iv["high"], "paper_data": data}
    return out


def claims(table: pd.DataFrame, paper: dict, st, shares: dict, strata: dict | None = None) -> dict:
    """Every quoted claim with its readings (:mod:`.readings`), the paper's interval (and its
    sensitivity to pairing, ``st.pairing``), the compatibility and testability verdicts
    (module doc), and, with ``strata`` (instance -> stratum name), every claim per stratum of
    ``st.strata``; ``st``: the ``stats`` section
    (:class:`vnrrt.evaluation.config.StatsConfig`); ``shares``: :func:`mask_shares`. The
    table may hold ``time_total`` (planning + inference, s): a third reading."""
    comparable = set(paper.get("comparable_columns", []))
    pairs = [_pair(table, paper, claim) for claim in paper["claims"]]
    tested = sum(p is not None for p in pairs)
    strict = bonferroni_level(st.level, tested)
    n_boot = claim_boot(st.bootstrap, st.tail_draws, strict)
    metrics = ["time_to_stop", "iterations"] + (["time_total"] if "time_total" in table else [])
    names = stratum_names(st.strata)
    rows = []
    for claim, pair in zip(paper["claims"], pairs, strict=True):
        stop = paper["tables"][claim["table"]]["stop"]
        iv = claim_interval(paper, claim, strict).as_dict()
        row = {**claim, "stop": stop, "comparable": claim["column"] in comparable, "paper": iv}
        row |= _judged(_readings(pair, metrics, n_boot, strict), claim, iv, strict)
        t = row["readings"].get(PAPERS)
        row["paper_data"] = None if t is None else compatibility(t["difference"])
        row["pairing"] = _paper_pairing(paper, claim, strict, st.pairing, row["time_to_stop"])
        if strata is not None:
            row["strata"] = _per_stratum(pair, strata, names, claim, iv, n_boot, strict)
        masked = ConfigKey.parse(claim["planner"]).tau is not None
        cell = (
            shares.get(stop, {}).get(claim["planner"], {}).get(claim["column"]) if masked else None
        )
        row["testability"] = testability(cell, st.untestable_endpoint_share, st.untestable_fallback)
        rows.append(row)
    tails = n_boot * (1 - strict) / 2
    return {"level": st.level, "claims": tested, "corrected_level": strict,
            "bootstrap": n_boot, "tail_draws": tails, "testability_rule": testability_rule(st),
            "pairing": list(st.pairing), "strata": names if strata is not None else [],
            "rows": rows}  # fmt: skip
