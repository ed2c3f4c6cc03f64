"""The report's reading of the budget curve ("What the curve says"): the VNRRT*/NRRT* gap and
its trend, whether VertexNet concentrates on the turning points, what this does to the
study's conclusion, and what an extrapolation to the paper's training budget can and cannot
claim. Sentences are chosen by the summary's numbers; every number is the summary's."""

from __future__ import annotations

import math

from vnrrt.evaluation.keys import label
from vnrrt.names import stop_name

SHOWN_STOP = "optimal"  # the paper's optimal-solution rule, the stop of its headline claims
METRIC = "time_to_stop"
TREND_WORDS = {
    "grows": "VNRRT* gains on NRRT* as the networks learn",
    "shrinks": "VNRRT* loses ground to NRRT* as the networks learn",
    "no clear trend": "no clear trend within the measured range",
    "differs between seeds": "no trend holds across the training seeds (their labels differ)",
}


def fmt_cell(cell: dict | None) -> str:
    """``1.23 [1.10, 1.37]``; ``n/a`` where there is no value (an interval may be absent)."""
    if cell is None or cell.get("speedup") is None:
        return "n/a"
    if cell.get("ci_low") is None or cell.get("ci_high") is None:
        return f"{cell['speedup']:.3g}"
    return f"{cell['speedup']:.3g} [{cell['ci_low']:.3g}, {cell['ci_high']:.3g}]"


def find_trend(summary: dict, base: str, plan: str, stop: str, metric: str) -> dict | None:
    """The trend of ``plan`` over ``base`` (key texts), or None."""
    for t in summary["trends"]:
        if (t["base"], t["planner"], t["stop"], t["metric"]) == (base, plan, stop, metric):
            return t
    return None


def _cell(c: dict | None) -> str:
    return fmt_cell(c)


def _side(cell: dict | None) -> str:
    """Where a ratio's CI lies: ``above`` 1, ``below`` 1 or ``around`` 1 (unknown)."""
    if cell is None or cell.get("ci_low") is None or cell.get("ci_high") is None:
        return "around"
    return "above" if cell["ci_low"] > 1 else "below" if cell["ci_high"] < 1 else "around"


def gap(summary: dict, key: str, stop: str) -> list[str]:
    """The ratio ``key`` / NRRT* at the smallest and the largest budget, and its trend."""
    s, first, last = summary["settings"], summary["budgets"][0], summary["budgets"][-1]
    a, b = first["ratios"][stop][METRIC][key], last["ratios"][stop][METRIC][key]
    lo, hi = first["images"], last["images"]
    span = f"Over {lo:,} to {hi:,} training images ({hi / lo:.3g}x)" if hi > lo else (
        f"At {hi:,} training images (one budget: no trend)")  # fmt: skip
    text = (f"{span}, the planning time of "
            f"{label(key)} relative to NRRT*, {stop_name(stop, s['eps'])} (median(NRRT*) / "
            f"median({label(key)}); above 1: {label(key)} faster), went from {_cell(a)} to "
            f"{_cell(b)}.")  # fmt: skip
    t = find_trend(summary, "nrrt_star", key, stop, METRIC)
    if t is not None and t["per_doubling"] is not None:
        factor = {"speedup": t["per_doubling"], "ci_low": t["ci_low"], "ci_high": t["ci_high"]}
        words = TREND_WORDS.get(t["verdict"], t["verdict"])
        text += f" Per doubling of the images it changed by a factor {_cell(factor)}: {words}."
    return [text, ""]


def concentration(summary: dict) -> list[str]:
    """VertexNet's (and the path network's) interior mass and AP, smallest to largest budget."""
    s, first, last = summary["settings"], summary["budgets"][0], summary["budgets"][-1]
    vertex, path = s["sources"].get("vnrrt_star"), s["sources"].get("nrrt_star")
    if vertex is None or path is None:
        return []

    def ratio(b, net, key):
        value = b["networks"][net]["heatmap"][key]["ratio"]
        return "n/a" if value is None else f"{value:.3g}x"

    names = {"mass_near_interior": "mass near the interior vertices",
             "interior_ap": "interior-vertex AP"}  # fmt: skip
    parts = [f"{what}: {vertex} {ratio(first, vertex, key)} to {ratio(last, vertex, key)}, "
             f"{path} {ratio(first, path, key)} to {ratio(last, path, key)}"
             for key, what in names.items()]  # fmt: skip
    v = last["networks"][vertex]["heatmap"]["mass_near_interior"]["ratio"]
    p = last["networks"][path]["heatmap"]["mass_near_interior"]["ratio"]
    more = "more" if v is not None and p is not None and v > p else "no more"
    return [f"Does VertexNet concentrate on the turning points? In multiples of a uniform map, "
            f"smallest to largest budget: {'; '.join(parts)}. At the largest budget VertexNet "
            f"puts {more} mass near the interior vertices than the path network.", ""]  # fmt: skip


def conclusion(summary: dict, key: str, stop: str) -> list[str]:
    """What the largest budget says of the study's conclusion (VNRRT* accelerates RRT* but
    less than NRRT*)."""
    last = summary["budgets"][-1]
    side = _side(last["ratios"][stop][METRIC][key])
    over = _side(last["speedups"][stop][METRIC][key])
    what = {
        "below": f"{label(key)} is still slower than NRRT* (CI below 1): the study's conclusion "
                 "(VertexNet accelerates RRT*, but less than the NRRT* network) stands at every "
                 "budget up to the largest measured",
        "above": f"{label(key)} is faster than NRRT* (CI above 1): the study's conclusion does "
                 "not hold at the largest budget measured",
        "around": f"{label(key)} and NRRT* do not differ clearly (CI contains 1): the study's "
                  "'less than NRRT*' is not shown at the largest budget measured",
    }[side]  # fmt: skip
    rrt = {"above": "faster than", "below": "slower than", "around": "not clearly faster than"}
    return [f"At the largest budget, {what}; {label(key)} is {rrt[over]} RRT* there.", ""]


def extrapolation(summary: dict) -> list[str]:
    """What the measured range can and cannot say about the paper's training budget."""
    s, budgets = summary["settings"], summary["budgets"]
    paper, lo, hi = s["paper_training_images"], budgets[0]["images"], budgets[-1]["images"]
    beyond = math.log2(paper / hi) if paper > 0 and hi > 0 else math.nan
    return [
        f"Extrapolation. The paper's networks saw at least {paper:,} images (its training set, "
        f"for several epochs; `data/paper/settings.yaml`), {beyond:.1f} doublings beyond the "
        f"largest budget here; the trends above are measured over {math.log2(hi / lo):.1f} "
        "doublings (none with one budget). They are not extended to the paper's budget, by a "
        "straight line or otherwise: no speed-up at that budget is a result of this report. "
        "The curve can say whether the gap moves, and whether VertexNet begins to concentrate "
        "on the turning points, within the measured range; it cannot say where the curves go "
        "beyond it, nor that they keep their direction (learning curves flatten, and the paper "
        "trains another network on other data).",
        "",
    ]


def reading(summary: dict) -> list[str]:
    """The section (module doc)."""
    s = summary["settings"]
    stop = SHOWN_STOP if SHOWN_STOP in s["stops"] else s["stops"][-1]
    keys = [k for k in s["ratio_keys"] if k == "vnrrt_star"] or s["ratio_keys"][:1]
    lines = ["## What the curve says", ""]
    for key in keys:
        lines += gap(summary, key, stop) + conclusion(summary, key, stop)
    return lines + concentration(summary) + extrapolation(summary)
