"""The budget curve's figure (``training_budget.md``): speed-ups over RRT* and the ratios to
NRRT* against the images each network saw in training, beside the networks' heatmap mass
near the interior vertices and near the path (multiples of a uniform map)."""

from __future__ import annotations

from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.ticker import NullLocator

from vnrrt.evaluation.keys import label
from vnrrt.names import level_name, stop_name
from vnrrt.viz.common import log_ticks, save_figure

MASSES = {"mass_near_interior": "interior vertices", "mass_near_path": "path"}
METRIC_NAMES = {"time_to_stop": "time", "iterations": "iterations"}


def _band(ax, x, cells: list[dict], name: str, **style) -> None:
    """One line (``speedup``) with its CI band (``ci_low``..``ci_high``; None: no band) and,
    pooled over training seeds, each seed's own value as a small dot (``per_seed``)."""
    y = [c["speedup"] for c in cells]
    lo = [np.nan if c["ci_low"] is None else c["ci_low"] for c in cells]
    hi = [np.nan if c["ci_high"] is None else c["ci_high"] for c in cells]
    (line,) = ax.plot(x, y, marker="o", ms=4, label=name, **style)
    ax.fill_between(x, lo, hi, color=line.get_color(), alpha=0.18, lw=0)
    seeds = [(xi, v) for xi, c in zip(x, cells, strict=True)
             for v in (c.get("per_seed") or {}).values()]  # fmt: skip
    if seeds:
        ax.scatter(*zip(*seeds, strict=True), s=6, color=line.get_color(), alpha=0.6, lw=0)


def _speedup_panel(ax, summary: dict, stop: str, metric: str) -> None:
    budgets, s = summary["budgets"], summary["settings"]
    x = [b["images"] for b in budgets]
    for key in s["keys"][1:]:
        _band(ax, x, [b["speedups"][stop][metric][key] for b in budgets], label(key))
    ax.set_title(f"over RRT*, {stop_name(stop, s['eps'])}", fontsize=9)


def _ratio_panel(ax, summary: dict, key: str, metric: str) -> None:
    budgets, s = summary["budgets"], summary["settings"]
    x = [b["images"] for b in budgets]
    for stop in s["stops"]:
        cells = [b["ratios"][stop][metric][key] for b in budgets]
        _band(ax, x, cells, stop_name(stop, s["eps"]), ls="--")
    ax.set_title(f"{label(key)} / NRRT* (paired)", fontsize=9)


def _mass_panel(ax, summary: dict) -> None:
    budgets = summary["budgets"]
    x = [b["images"] for b in budgets]
    for k, network in enumerate(budgets[0]["networks"]):
        for key, where in MASSES.items():
            y = [b["networks"][network]["heatmap"][key]["ratio"] for b in budgets]
            style = "-" if key == "mass_near_interior" else ":"
            ax.plot(x, y, marker="s", ms=4, color=f"C{k}", ls=style,
                    label=f"{network}: near the {where}")  # fmt: skip
    radius = summary["settings"]["heatmap"]["radius"]
    ax.set_title(f"heatmap mass within {radius:g} px, x a uniform map's", fontsize=9)


def budget_figure(summary: dict, metric: str):
    """Row 1: the speed-up over RRT* (``metric``) of each learned planner per stop rule
    against the images seen (log axes; bands: CI); row 2: VNRRT* and M-VNRRT* over NRRT*,
    one line per stop rule, and the networks' heatmap mass (interior vertices, path) in
    multiples of a uniform map. The run's eps, CI level and mass radius come from
    ``summary["settings"]``. Returns the figure."""
    s = summary["settings"]
    stops, ratio_keys = s["stops"], s["ratio_keys"]
    cols = max(len(stops), len(ratio_keys) + 1)
    fig, axes = plt.subplots(2, cols, figsize=(4.3 * cols, 7.6), squeeze=False)
    for j, stop in enumerate(stops):
        _speedup_panel(axes[0, j], summary, stop, metric)
    for j, key in enumerate(ratio_keys):
        _ratio_panel(axes[1, j], summary, key, metric)
    _mass_panel(axes[1, len(ratio_keys)], summary)
    used = [(0, j) for j in range(len(stops))] + [(1, j) for j in range(len(ratio_keys) + 1)]
    for i, j in np.ndindex(axes.shape):
        ax = axes[i, j]
        if (i, j) not in used:
            ax.set_visible(False)
            continue
        if (i, j) != (1, len(ratio_keys)):
            ax.axhline(1.0, color="grey", lw=0.8)
        log_ticks(ax.xaxis)
        log_ticks(ax.yaxis)
        images = [b["images"] for b in summary["budgets"]]
        ax.set_xticks(images, [f"{v:,}" for v in images], fontsize=7)
        ax.xaxis.set_minor_locator(NullLocator())
        ax.set_xlabel("training images seen")
        ax.legend(fontsize=7)
    axes[0, 0].set_ylabel(f"speed-up ({METRIC_NAMES[metric]})")
    axes[1, 0].set_ylabel(f"ratio ({METRIC_NAMES[metric]})")
    seeds = summary.get("seeds", [s["train_seed"]])
    dots = "; dots: each seed's" if len(seeds) > 1 else ""
    seeds = ", ".join(str(v) for v in seeds)
    fig.suptitle(f"The networks over a training budget: {METRIC_NAMES[metric]} "
                 f"(bands: {level_name(s['level'])} CI{dots}; training seeds {seeds})",
                 fontsize=10)  # fmt: skip
    fig.tight_layout()
    return fig


def save_budget_figure(out_png: str | Path, summary: dict, metric: str) -> None:
    """:func:`budget_figure` saved as a PNG."""
    save_figure(budget_figure(summary, metric), out_png)
