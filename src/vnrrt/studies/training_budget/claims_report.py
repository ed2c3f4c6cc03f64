"""The report's section on the paper's claims over the training seeds' networks
(:mod:`.claims`), from the summary alone."""

from __future__ import annotations

from vnrrt.names import level_name
from vnrrt.studies.paper_comparison.claims import improvement, on_its_map


def _seed_cell(seed: str, cell: dict) -> str:
    """One seed's time reading, its verdict and, if untestable, why."""
    t = cell["time_to_stop"]
    text = f"{seed}: {improvement(t)}, {t['verdict']}"
    return text if cell["testability"]["testable"] else f"{text} (untestable)"


def seed_claims_section(summary: dict) -> list[str]:
    """The section (module doc); nothing where the summary has no claims."""
    c = summary.get("claims")
    if not c or not c["rows"]:
        return []
    seeds = ", ".join(str(s) for s in c["seeds"])
    steps = summary["budgets"][-1]["steps"]
    head = ["claim", "paper", "pooled over seeds: time [CI]", "verdict (pooled)",
            "pooled: iterations [CI]", "each seed: time [CI], verdict",
            "seeds whose sampler tests the claim"]  # fmt: skip
    lines = ["## The paper's claims over training seeds", "",
             f"The paper's quoted claims, read at the largest budget ({steps:,} "
             f"steps) over the networks of training seeds {seeds}: "
             "pooled, the interval resamples the seeds, then base maps, instances and trials, so "
             "it includes the training variance; beside it, each seed's network pair alone. "
             "Planning time, our estimand (geometric mean over instances of median(baseline) / "
             f"median(planner)), at {level_name(c['corrected_level'])} (Bonferroni over the "
             f"{len(c['rows'])} claims read here; {c['bootstrap']:,} resamples); verdicts as in "
             "the paper comparison, against the paper's value and its own interval; a claim on "
             "a named map is 'different map: not comparable' (ours are not the paper's maps). "
             f"A masked claim is untestable with a network when {c['untestable_rule']}.",
             "", "| " + " | ".join(head) + " |", "|" + " --- |" * len(head)]  # fmt: skip
    for row in c["rows"]:
        pooled = row["pooled"]
        per = "; ".join(_seed_cell(k, v) for k, v in row["per_seed"].items())
        verdict = on_its_map(pooled["time_to_stop"]["verdict"], row["comparable"])
        cells = [row["text"], f"{row['quoted']:+.2%}", improvement(pooled["time_to_stop"]),
                 verdict, improvement(pooled["iterations"]), per,
                 f"{row['testable_seeds']} of {len(row['per_seed'])}"]  # fmt: skip
        lines.append("| " + " | ".join(cells) + " |")
    return [*lines, ""]
