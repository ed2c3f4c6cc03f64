"""A claim's verdict reads the same in the report and on the MLflow dashboard: the report's
words (different map, the iterations' verdict where it differs) and its unit (percent)."""

from vnrrt.studies.paper_comparison.claims import improvement, verdict_text
from vnrrt.studies.paper_comparison.run_text import claim_tags, verdict_table

READING = {"speedup": 1.5, "ci_low": 1.25, "ci_high": 2.0, "verdict": "reproduced"}


def row(comparable=True, iterations="reproduced"):
    it = dict(READING, verdict=iterations)
    return {"text": "VNRRT* is faster", "planner": "vnrrt_star", "baseline": "nrrt_star",
            "column": "random" if comparable else "map_2", "table": "optimal_time",
            "comparable": comparable, "verdict": "reproduced", "time_to_stop": READING,
            "iterations": it, "paper_data": "compatible",
            "testability": {"testable": True, "why": ""}}  # fmt: skip


def test_the_verdict_says_where_time_and_iterations_disagree_and_the_map():
    assert verdict_text(row()) == "reproduced"
    assert verdict_text(row(iterations="no clear effect")) == (
        "reproduced; on iterations: no clear effect"
    )
    assert verdict_text(row(comparable=False)) == "different map: not comparable (reproduced)"
    assert improvement(READING) == "+50.0% [+25.0%, +100.0%]"


def test_the_dashboard_uses_the_reports_words_and_units():
    r = row(comparable=False, iterations="reversed")
    tags = claim_tags([r])
    (verdict,) = [v for k, v in tags.items() if k.startswith("verdict/") and k.count("/") == 1]
    assert verdict == "different map: not comparable (reproduced; on iterations: reversed)"
    line = verdict_table([r])[-1]
    assert "+50.0% [+25.0%, +100.0%]" in line and f"**{verdict}**" in line and "x [" not in line
