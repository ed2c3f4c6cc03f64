"""The paper's claims read over several trained networks: at one training budget (the
largest of the curve, the pipeline's own training), every seed's network pair through the
same instances and trial seeds, pooled.

Each claim whose configurations and map set the budget trials run (RRT*, NRRT*, VNRRT*,
M-VNRRT* at ``planner.tau``; the random maps and the named maps) is read as the paper
comparison reads it
(:mod:`vnrrt.studies.paper_comparison.claims`): planning time and iterations, our estimand
(geometric mean over instances of median(baseline) / median(planner)), at the family-wise
level over the claims read here (Bonferroni), the verdict judged against the paper's value
and, by the interval of the difference, against the paper's own interval; a claim off the
paper's comparable map set (a named map: ours are not the paper's) is marked so. The pooled
interval resamples training seeds, then base maps, instances and trials
(:func:`vnrrt.evaluation.seeds.seed_compare`): it includes the training variance. Beside it,
every seed's own reading (its network pair alone: base maps, instances and trials
resampled) with its verdict, and whether each seed's masked sampler tests the mask.
"""

from __future__ import annotations

from vnrrt.evaluation.seeds import seed_compare
from vnrrt.evaluation.stats import bonferroni_level, compare
from vnrrt.studies.paper_comparison.claims import (
    claim_boot,
    mask_shares,
    testability,
    testability_rule,
)
from vnrrt.studies.paper_comparison.paper_noise import claim_interval
from vnrrt.studies.paper_comparison.readings import difference, reading_verdict
from vnrrt.studies.training_budget.pooled import paired_rows

METRICS = ("time_to_stop", "iterations")


def readable(paper: dict, runs: list[dict]) -> list[dict]:
    """The quoted claims whose baseline and planner ran in every run of ``runs`` on the
    claim's map set (column) at its stop rule (``paper["tables"]``)."""
    ran = set.intersection(*(set(zip(r["trials"]["key"], r["trials"]["map_set"],
                                      r["trials"]["stop"])) for r in runs))  # fmt: skip

    def has(c: dict, key: str) -> bool:
        return (key, c["column"], paper["tables"][c["table"]]["stop"]) in ran

    return [c for c in paper["claims"] if has(c, c["baseline"]) and has(c, c["planner"])]


def _verdict(est: float, lo: float, hi: float, claim: dict, iv: dict, level: float) -> dict:
    """A reading (ratio ``est`` in ``[lo, hi]``) judged against the quoted value and the
    paper's interval ``iv`` (:func:`vnrrt.studies.paper_comparison.readings.reading_verdict`)."""
    diff = difference((est, lo, hi), iv, level)
    v = reading_verdict(claim["quoted"], lo - 1, hi - 1, diff)
    return {"speedup": est, "ci_low": lo, "ci_high": hi, "difference": diff, "verdict": v}


def _per_seed(runs: list[dict], claim: dict, stop: str, iv: dict, n_boot: int, level: float,
              st) -> dict:  # fmt: skip
    """Each seed's own reading on time (its verdict), iterations, and testability."""
    out = {}
    for run in runs:
        t = run["trials"]
        sel = t[(t["map_set"] == claim["column"]) & (t["stop"] == stop)]
        base, plan = sel[sel["key"] == claim["baseline"]], sel[sel["key"] == claim["planner"]]
        cell = {}
        for metric in METRICS:
            c = compare(base, plan, metric, n_boot=n_boot, level=level)
            cell[metric] = _verdict(c.speedup, c.ci_low, c.ci_high, claim, iv, level)
        shares = mask_shares(sel).get(stop, {}).get(claim["planner"], {}).get(claim["column"])
        masked = "@" in claim["planner"]
        cell["testability"] = testability(
            shares if masked else None, st.untestable_endpoint_share, st.untestable_fallback
        )
        out[str(run["seed"])] = cell
    return out


def seed_claims(runs: list[dict], paper: dict, st) -> dict:
    """The claims over the seeds' runs ``runs`` (each ``seed`` and ``trials``, one budget;
    module doc). ``st``: the ``stats`` section; ``paper``: the paper's tables (its claims,
    each table's stop rule, the comparable map sets). Returns ``level``,
    ``corrected_level``, ``bootstrap``, ``seeds`` and one row per claim: the claim's
    fields, ``comparable`` (its map set is the paper's comparable one), ``paper`` (its
    interval), ``pooled`` ``{metric: reading}`` and ``per_seed``."""
    claims = readable(paper, runs)
    comparable = set(paper.get("comparable_columns", []))
    strict = bonferroni_level(st.level, max(len(claims), 1))
    n_boot = claim_boot(st.bootstrap, st.tail_draws, strict)
    rows = []
    for claim in claims:
        stop = paper["tables"][claim["table"]]["stop"]
        iv = claim_interval(paper, claim, strict).as_dict()
        pooled = {}
        for metric in METRICS:
            pairs = paired_rows(runs, claim["baseline"], claim["planner"], stop, metric,
                                map_set=claim["column"])  # fmt: skip
            c = seed_compare(pairs, metric, n_boot=n_boot, level=strict)
            pooled[metric] = _verdict(c["speedup"], c["ci_low"], c["ci_high"], claim, iv, strict)
            pooled[metric]["per_seed_point"] = c["per_seed"]
        per_seed = _per_seed(runs, claim, stop, iv, n_boot, strict, st)
        testable = sum(s["testability"]["testable"] for s in per_seed.values())
        rows.append({**claim, "stop": stop, "comparable": claim["column"] in comparable,
                     "paper": iv, "pooled": pooled, "per_seed": per_seed,
                     "testable_seeds": testable})  # fmt: skip
    return {"level": st.level, "corrected_level": strict, "bootstrap": n_boot,
            "seeds": [int(r["seed"]) for r in runs], "rows": rows,
            "untestable_rule": testability_rule(st)}  # fmt: skip
