"""The report's sections on the networks: their heatmap metrics (with the settings they were
computed with) and their inference time beside the planning time."""

from __future__ import annotations

import math
from dataclasses import dataclass

from vnrrt.evaluation.keys import is_informed, label


def num(v: float, digits: int = 3) -> str:
    return "n/a" if v is None or not math.isfinite(v) else f"{v:.{digits}g}"


@dataclass(frozen=True)
class MetricSettings:
    """How the networks' heatmap metrics were computed (``predict``): "near" within
    ``radius`` px, recall at probability ``tau``, AP against targets dilated by
    ``ap_radius`` px with start/goal disks of ``endpoint_radius`` px left out."""

    radius: float
    tau: float
    ap_radius: float
    endpoint_radius: float


def metric_settings(settings: dict) -> MetricSettings:
    """The :class:`MetricSettings` that ``predict.json`` records (its ``settings``)."""
    keys = ("radius", "tau", "ap_radius", "endpoint_radius")
    return MetricSettings(*(float(settings[k]) for k in keys))


def inference_table(summary: dict, inference_ms: dict[str, float], sources: dict[str, str]) -> str:
    """Median planning time on random maps beside network inference per map."""
    lines = [
        "| configuration | stop rule | planning, median (ms) | inference per map (ms, CPU) "
        "| planning + inference (ms) |",
        "| --- | --- | --- | --- | --- |",
    ]
    for stop in ("initial", "optimal"):
        for key, sets in summary["cells"].get(stop, {}).items():
            if is_informed(key):
                continue
            s = sets.get("random", {}).get("time_to_stop")
            if s is None:
                continue
            net = sources.get(key)
            inf = inference_ms.get(net, 0.0) if net else 0.0
            plan_ms = 1e3 * s["median"]
            lines.append(
                f"| {label(key)} | {stop} | {num(plan_ms)} | "
                f"{num(inf) if net else '0 (no network)'} | {num(plan_ms + inf)} |"
            )
    return "\n".join(lines)


NETWORK_COLUMNS = [  # (header, metric, its uniform baseline or None)
    ("interior recall", "interior_recall", None),
    ("interior AP", "interior_ap", None),
    ("path AP", "path_ap", None),
    ("mass near interior (x uniform)", "mass_near_interior", "mass_near_interior_uniform"),
    ("mass near path (x uniform)", "mass_near_path", "mass_near_path_uniform"),
    ("mass on start/goal", "mass_on_endpoints", None),
]


def networks_table(networks: dict[str, dict]) -> str:
    """The heatmap metrics of each network (``predict.json``: ``<set>/<metric>``) on the
    test and named maps, as shares with multiples of a uniform map's where it has one."""
    taus = sorted({k.rsplit("_tau", 1)[1] for m in networks.values() for k in m
                   if "mass_near_interior_tau" in k})  # fmt: skip
    cols = [*NETWORK_COLUMNS, *((f"interior, tau {t.replace('_', '.')} mask (x uniform)",
            f"mass_near_interior_tau{t}", "mass_near_interior_uniform") for t in taus)]  # fmt: skip
    lines = ["| network | maps | " + " | ".join(c[0] for c in cols) + " |",
             "|" + "---|" * (len(cols) + 2)]  # fmt: skip
    for net, m in networks.items():
        for group in ("test", "named"):
            vals = []
            for _, key, base in cols:
                v, u = m.get(f"{group}/{key}"), m.get(f"{group}/{base}") if base else None
                vals.append("—" if v is None else num(v) + (f" ({v / u:.1f}x)" if u else ""))
            lines.append(f"| {net} | {group} | " + " | ".join(vals) + " |")
    return "\n".join(lines)


def networks_section(networks: dict[str, dict], ms: MetricSettings) -> list[str]:
    """The report's section on what the networks learnt (empty without metrics), with the
    settings ``ms`` the metrics were computed with."""
    if not networks:
        return []
    return [
        "## The networks' heatmaps",
        "",
        networks_table(networks),
        "",
        "Interior: the A* label's vertices other than start and goal (what a vertex sampler "
        f"should find; the start and goal are drawn in the input). Recall at probability "
        f"{ms.tau:g} within {ms.radius:g} px; AP over pixels against the interior vertices "
        f"(path cells), each dilated by {ms.ap_radius:g} px, the start/goal disks (radius "
        f"{ms.endpoint_radius:g} px) left out of the interior AP; 'mass near': the share of "
        f"the heatmap within {ms.radius:g} px, beside a uniform map's; the tau columns after "
        "M-VNRRT*'s mask (an image left empty counts as uniform).",
        "",
    ]
