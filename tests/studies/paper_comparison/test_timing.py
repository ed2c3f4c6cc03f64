"""The report's timing-noise section: present only where RRT* was timed twice; an ablation's
claims against the default run, with a verdict that moved within the noise flagged."""

from vnrrt.names import map_set_title
from vnrrt.studies.paper_comparison.timing import timing_section

READING = {"speedup": 1.01, "ci_low": 0.97, "ci_high": 1.06, "band_low": 1 / 1.06,
           "band_high": 1.06, "trials": 40}  # fmt: skip
NOISE = {"optimal": {"random": READING}}
SUMMARY = {"eps": 0.01, "level": 0.95, "claims": {"corrected_level": 0.99375},
           "timing_noise": NOISE}  # fmt: skip


def _change(text, ratio, within, before="reproduced", now="no clear effect", same=True):
    return {"text": text, "before": 1.3, "now": 1.3 * ratio, "ratio": ratio,
            "within_noise": within, "iterations_same": same, "verdict_before": before,
            "verdict_now": now}  # fmt: skip


def test_the_section_reads_rrt_star_against_itself():
    text = "\n".join(timing_section(SUMMARY, None, ""))
    assert "## The machine's timing noise" in text
    assert (
        f"| {map_set_title('random')} | 1.010x [0.970x, 1.060x] | 0.943x to 1.060x | 40 |" in text
    )
    assert "Against your default run" not in text
    assert timing_section({**SUMMARY, "timing_noise": {}}, None, "") == []
    assert timing_section({k: v for k, v in SUMMARY.items() if k != "timing_noise"}, None, "") == []


def test_an_ablation_flags_a_verdict_that_moved_within_the_noise():
    changes = [_change("moved by noise", 0.97, True),
               _change("same verdict", 1.02, True, now="reproduced"),
               _change("moved for real", 1.5, False, same=False),
               _change("no band", 1.1, None)]  # fmt: skip
    lines = timing_section(SUMMARY, changes, "tau=0.7")
    text = "\n".join(lines)
    assert "### Against your default run (tau=0.7)" in text
    row = {line.split(" | ")[0].strip("| "): line for line in lines if line.startswith("| ")}
    assert "**verdict moved within timing noise**" in row["moved by noise"]
    assert "identical: re-timing only" in row["moved by noise"]
    assert "| -3.0% |" in row["moved by noise"]
    assert "| yes |" in row["same verdict"]
    assert (
        "no: beyond the noise" in row["moved for real"] and "| changed |" in row["moved for real"]
    )
    assert "no band" in row["no band"]
