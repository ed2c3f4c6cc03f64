"""``headline.json``: the few numbers of ``dvc metrics show`` (the verdict counts, the
networks' quality, the median planning times, the machine), made by stage ``report`` from the
summary (:func:`vnrrt.studies.paper_comparison.summary.analyze`)."""

from __future__ import annotations

from vnrrt.evaluation.keys import ConfigKey
from vnrrt.studies.paper_comparison.claims import CONTRADICTS

VERDICT_GROUPS = ("reproduced", "same direction", "no clear effect", "reversed")
TARGET_MASKS = {"vertex": "interior", "path": "path"}  # what each network target is for


HEADLINE_PLANNERS = {"rrt_star": "rrt", "nrrt_star": "nrrt", "vnrrt_star": "vnrrt",
                     "m_vnrrt_star": "m"}  # fmt: skip


def headline(summary: dict, networks: dict, tau: float, machine: str | None = None) -> dict:
    """The few numbers of ``dvc metrics show`` (one line each under ~300 characters in a
    terminal; the full tables are in the report and MLflow): the counts of verdicts
    (:data:`VERDICT_KEYS`) on the paper's testable claims (an untestable claim gets no
    verdict in the counts), each network's mass near what it is for (a vertex network: the
    interior vertices; a path network: the path) as a multiple of a uniform map's, the
    vertex networks' interior-vertex AP, the median planning time (ms) to the A*-relative
    optimum on random maps of RRT*, NRRT*, VNRRT* and M-VNRRT* at ``tau`` (``planner.tau``),
    and the ``machine`` whose timings these are (None: not recorded). ``networks``:
    ``predict.json``'s metrics per network."""
    out: dict = {"mass_x": {}, "opt_ms": {}, "interior_ap": {}}
    for net, m in networks.items():
        target = TARGET_MASKS[m["target"]]
        share, uniform = (
            m.get(f"test/mass_near_{target}"),
            m.get(f"test/mass_near_{target}_uniform"),
        )
        if share is not None and uniform:
            out["mass_x"][net] = round(share / uniform, 3)
        if "test/interior_ap" in m and m["target"] == "vertex":
            out["interior_ap"][net] = round(m["test/interior_ap"], 4)
    for text, sets in summary["cells"].get("optimal", {}).items():
        s, key = sets.get("random", {}).get("time_to_stop"), ConfigKey.parse(text)
        protocol = ConfigKey(key.planner, tau if key.planner == "m_vnrrt_star" else None)
        if s is not None and key == protocol:
            out["opt_ms"][HEADLINE_PLANNERS[key.planner]] = round(1e3 * s["median"], 3)
    rows = [r for r in summary["claims"]["rows"] if r["time_to_stop"]]
    testable = [r for r in rows if r["testability"]["testable"]]
    verdicts = [r["verdict"] for r in testable]  # one per testable claim; untestable: none
    for group in VERDICT_GROUPS:
        out[VERDICT_KEYS[group]] = sum(v.startswith(group) for v in verdicts)
    out["testable"], out["untestable"] = len(testable), len(rows) - len(testable)
    out["contradicting"] = sum(r["paper_data"] == CONTRADICTS for r in testable)
    return out | ({"machine": machine} if machine else {})


VERDICT_KEYS = {"reproduced": "reproduced", "same direction": "same_dir",
                "no clear effect": "no_effect", "reversed": "reversed"}  # fmt: skip
