"""What the MLflow evaluation run says (:mod:`.runs` logs it): metric names a reviewer can
read, the claims as metrics and tags, and the run's markdown description. Pure functions of
the summary (``data/<scale>/summary.json``) and the headline metrics.

Metric names say map set, stop rule, statistic and planner, in that order:

* ``random_maps/within_1pct_of_astar/median_ms/vnrrt_star``: the median planning time (ms)
  on the random test maps, stopping within 1% (``planner.eps``) of the A* length, of VNRRT*
  (``m_vnrrt_star_tau0.5``: M-VNRRT* at tau 0.5; ``_max``/``_noends``: its mask variants;
  ``_nrrtnet``: another network's heatmap; ``_informed``; stops ``initial_solution`` and
  ``within_1pct_of_exact_optimum``); the nested runs hold every map set and statistic;
* ``random_maps/heatmap/mass_near_target_x_uniform/vertexnet``: a network's heatmap mass near
  what it is for (interior vertices; the path for the path network) over a uniform map's,
  and ``random_maps/heatmap/interior_vertex_ap/vertexnet``;
* ``claims/<claim>/<reading>/speedup`` with ``ci_low`` and ``ci_high`` (the geometric-mean
  speed-up over the baseline and its CI at the corrected level), ``ratio_of_means`` with
  ``rom_ci_low``, ``rom_ci_high``; ``claims/<claim>/paper/ratio_of_means`` with the paper's
  own interval; ``<claim>`` is ``<paper table>.<map set>.<planner>_vs_<baseline>``
  (``optimal_time.random.vnrrt_star_vs_nrrt_star``), ``<reading>`` ``planning_time`` (the
  verdict's), ``iterations`` or ``planning_plus_inference_time``;
* ``claims/count/<verdict>``: how many claims got each verdict.

Tags: ``verdict/<claim>`` (the claim's verdict), ``verdict/<claim>/<reading>``,
``paper_data/<claim>``, ``testable/<claim>`` and ``claim/<claim>`` (the paper's words).
"""

from __future__ import annotations

from vnrrt.evaluation.keys import ConfigKey
from vnrrt.names import stop_name, stop_slug
from vnrrt.studies.paper_comparison.claims import (
    COMPATIBLE,
    CONTRADICTS,
    improvement,
    verdict_text,
)
from vnrrt.tracking.experiments import metric_name

READINGS = {"time_to_stop": "planning_time", "iterations": "iterations",
            "time_total": "planning_plus_inference_time"}  # fmt: skip
STATS = ("speedup", "ci_low", "ci_high", "ratio_of_means", "rom_ci_low", "rom_ci_high")
HEATMAP_NAMES = {
    "mass_x": "mass_near_target_x_uniform",
    "interior_ap": "interior_vertex_ap",
}
PAPER_DATA = {COMPATIBLE: "compatible", CONTRADICTS: "contradicts"}  # the table's short words
VERDICT_COUNTS = {"reproduced": "reproduced", "same_dir": "same_direction",
                  "no_effect": "no_clear_effect", "reversed": "reversed"}  # fmt: skip


def planner_key(text: str) -> str:
    """A configuration as a metric-name part: ``m_vnrrt_star_tau0.5_max``, ``vnrrt_star``,
    ``nrrt_star_informed``, ``m_vnrrt_star_tau0.5_nrrtnet``."""
    k = ConfigKey.parse(text)
    out = k.planner + ("" if k.tau is None else f"_tau{k.tau:g}")
    out += f"_{k.mask}" if k.mask else ""
    out += "" if k.mix is None else f"_mix{k.mix:g}"
    out += f"_{k.source}" if k.named_source else ""
    return metric_name(out + ("_free" if k.free else "") + ("_informed" if k.informed else ""))


def claim_key(row: dict) -> str:
    """``optimal_time.random.vnrrt_star_vs_nrrt_star``: a claim's paper table, map set,
    planner and baseline."""
    return f"{row['table']}.{row['column']}.{planner_key(row['planner'])}_vs_" + planner_key(
        row["baseline"]
    )


def headline_metrics(summary: dict, headline: dict) -> dict[str, float]:
    """The run's own metrics (module doc) from the summary and the headline metrics
    (``headline.json``)."""
    eps, out = summary["eps"], {}
    for stop, per_key in summary["cells"].items():
        for text, sets in per_key.items():
            s = sets.get("random", {}).get("time_to_stop")
            if s is not None and s["median"] is not None and not ConfigKey.parse(text).informed:
                place = ("random_maps", stop_slug(stop, eps), "median_ms", planner_key(text))
                out[metric_name(*place)] = 1e3 * s["median"]
    for key, name in HEATMAP_NAMES.items():
        for net, value in headline.get(key, {}).items():
            out[metric_name("random_maps", "heatmap", name, net)] = float(value)
    for key, name in VERDICT_COUNTS.items():
        out[f"claims/count/{name}"] = float(headline.get(key, 0))
    out["claims/count/testable"] = float(headline["testable"])
    out["claims/count/contradicting_paper_data"] = float(headline["contradicting"])
    return out | claim_metrics(summary["claims"]["rows"])


def claim_metrics(rows: list[dict]) -> dict[str, float]:
    """Per claim and reading, the speed-up, ratio of means and their CI bounds; per claim
    the paper's ratio of means and interval (module doc). Missing readings and non-finite
    bounds are left out."""
    import math

    out = {}
    for row in rows:
        c = f"claims/{claim_key(row)}"
        for reading, name in READINGS.items():
            for stat in STATS if row.get(reading) else ():
                v = row[reading][stat]
                if v is not None and math.isfinite(v):
                    out[f"{c}/{name}/{stat}"] = float(v)
        p = row["paper"]
        paper = {"ratio_of_means": p["improvement"], "ci_low": p["low"], "ci_high": p["high"]}
        out |= {f"{c}/paper/{k}": 1 + v for k, v in paper.items() if math.isfinite(v)}
    return out


def claim_tags(rows: list[dict]) -> dict[str, str]:
    """Per claim: its verdict, each reading's verdict, the paper-data and testability
    verdicts and the paper's words (module doc)."""
    out = {}
    for row in rows:
        c = claim_key(row)
        out[f"verdict/{c}"] = verdict_text(row)
        for reading, name in READINGS.items():
            if row.get(reading):
                out[f"verdict/{c}/{name}"] = row[reading]["verdict"]
        out[f"paper_data/{c}"] = row["paper_data"] or "no data"
        t = row["testability"]
        out[f"testable/{c}"] = "true" if t["testable"] else f"false: {t['why']}"
        out[f"claim/{c}"] = row["text"]
    return out


def verdict_table(rows: list[dict]) -> list[str]:
    """The claims as a markdown table: the paper's words, our speed-up and CI on time (the
    verdict's reading) and on iterations, the verdict, whether our ratio of means is
    compatible with the paper's own data, and whether the claim is testable here."""
    lines = [
        "| claim (the paper's words) | time [CI] | iterations [CI] | verdict | paper's data | "
        "testable |",
        "| --- | --- | --- | --- | --- | --- |",
    ]
    for row in rows:
        t, it = row.get("time_to_stop"), row.get("iterations")
        testable = "yes" if row["testability"]["testable"] else "no"
        data = PAPER_DATA.get(row["paper_data"], "no data")
        lines.append(
            f"| {row['text']} | {_ci(t)} | {_ci(it)} | **{verdict_text(row)}** | {data} | "
            f"{testable} |"
        )
    return lines


def _ci(reading: dict | None) -> str:
    """A reading as the report shows it (improvement in percent with its CI)."""
    return improvement(reading) if reading else "no data"


def describe(summary: dict, scale: str, links: list[str], figure: str | None) -> str:
    """The run's markdown description: what it is, the verdict table, the lineage
    ``links`` (markdown lines) and ``figure`` (a URL of Fig. 5, shown at the end)."""
    claims = summary["claims"]
    level = f"{100 * claims['corrected_level']:.4g}%"
    parts = [
        f"**The paper comparison at scale `{scale}`**: each claim the paper quotes, tested on "
        "this run's trials. Improvement (as in the report): the geometric mean over instances "
        f"of median(baseline) / median(planner), minus 1, with its {level} CI (Bonferroni "
        f"over {claims['claims']} claims); "
        f"the stop rules of the claims: {stop_name('initial', summary['eps'])}, "
        f"{stop_name('optimal', summary['eps'])}. The full report: `paper_comparison.html` "
        "(figures inline) or `paper_comparison.md` under Artifacts.",
        "",
        *verdict_table(claims["rows"]),
        "",
        *links,
    ]
    if figure:
        parts += ["", f"![Fig. 5: improvement over RRT*]({figure})"]
    return "\n".join(parts) + "\n"
