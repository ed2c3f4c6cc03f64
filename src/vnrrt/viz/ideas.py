"""Figures of "what each sampling idea can give": the heatmap-quality curve and the regime
sweep's speed-ups."""

from __future__ import annotations

from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np
import pandas as pd

from vnrrt.evaluation.keys import is_informed, label
from vnrrt.names import level_name, stop_name
from vnrrt.studies.sampling_ideas.summary import sweep_columns
from vnrrt.viz.common import log_ticks, save_figure

QUALITY_STOPS = ("initial", "optimal", "optimal_any_angle")

IDEA_NAMES = {"path": "path envelope", "vertex": "vertex envelope"}
IDEA_COLORS = {"path": "C0", "vertex": "C1"}  # the same idea, the same colour in every panel


def quality_figure(
    curves: pd.DataFrame, networks: pd.DataFrame, settings: dict, metric: str = "iterations"
):
    """Speed-up over RRT* (log axis, whiskers: CI) against the heatmap's mass near its
    target in multiples of a uniform map's (``x_uniform``), one curve per idea's envelope
    chosen for the panel's stop rule (rows with ``own``; points: signal fractions q of its
    ``member``; one colour per idea, a legend per panel), one panel per stop rule; the
    trained networks as labelled stars at their own measured mass. ``settings``: the
    study's ``eps``, ``level`` and mass ``radius`` (px), named on the figure. Returns it."""
    eps = settings["eps"]
    stops = [s for s in QUALITY_STOPS if s in set(curves["stop"])]
    fig, axes = plt.subplots(1, len(stops), figsize=(4.6 * len(stops), 4.2), squeeze=False)
    for ax, stop in zip(axes[0], stops, strict=True):
        sub = curves[(curves["stop"] == stop) & (curves["metric"] == metric) & curves["own"]]
        for (idea, conf), rows in sub.groupby(["idea", "member"], sort=False):
            rows = rows.dropna(subset=["x_uniform"]).sort_values("x_uniform")
            err = [rows["speedup"] - rows["ci_low"], rows["ci_high"] - rows["speedup"]]
            name = f"{label(conf)}, {IDEA_NAMES.get(idea, idea)}"
            ax.errorbar(
                rows["x_uniform"],
                rows["speedup"],
                yerr=err,
                marker="o",
                ms=3,
                capsize=2,
                label=name,
                color=IDEA_COLORS.get(idea),
            )
        nets = (
            networks
            if networks.empty
            else networks[(networks["stop"] == stop) & (networks["metric"] == metric)]
        )
        # the curves are plain (not informed) samplers: informed networks are not on them
        nets = nets[~nets["configuration"].map(is_informed).astype(bool)].sort_values("speedup")
        placed: list[float] = []  # log10 heights of the labels so far: close ones stacked
        for _, row in nets.iterrows():
            ax.plot(row["x_uniform"], row["speedup"], "*", ms=12, color="black")
            y = float(np.log10(row["speedup"]))
            lift = sum(abs(y - other) < 0.05 for other in placed)
            placed.append(y)
            ax.annotate(
                label(row["configuration"]),
                (row["x_uniform"], row["speedup"]),
                fontsize=7,
                xytext=(4, 4 + 9 * lift),
                textcoords="offset points",
            )
        ax.axhline(1.0, color="grey", lw=0.8)
        log_ticks(ax.xaxis)
        log_ticks(ax.yaxis)
        ax.set_xlabel(
            f"heatmap mass within {settings['radius']:g} px of its target (x a uniform map's)"
        )
        ax.set_title(stop_name(stop, eps), fontsize=9)
        if ax.get_legend_handles_labels()[0]:  # each stop rule has envelopes of its own
            ax.legend(loc="upper left", fontsize=6)
    axes[0, 0].set_ylabel(f"speed-up over RRT* ({metric.replace('time_to_stop', 'time')})")
    fig.suptitle(
        "How good must a heatmap be? Speed-up against heatmap quality "
        "(points: signal fraction q; stars: the trained networks; whiskers: "
        f"{level_name(settings['level'])} CI)",
        fontsize=9,
    )
    fig.tight_layout()
    return fig


def regime_figure(cells: pd.DataFrame, stop: str, settings: dict):
    """Speed-up over RRT* per regime cell (rows) and configuration run in every cell
    (columns, :func:`vnrrt.studies.sampling_ideas.summary.sweep_columns`), log colour
    scale, ``*`` where the CI excludes 1; ``settings``: the study's ``eps`` and ``level``.
    Returns the figure."""
    eps = settings["eps"]
    sub = cells[cells["stop"] == stop]
    regimes = list(dict.fromkeys(sub["regime"]))
    confs = sweep_columns(sub.to_dict("records"))
    sub = sub[sub["configuration"].isin(confs)]
    grid = np.full((len(regimes), len(confs)), np.nan)
    sig = np.zeros_like(grid, bool)
    for _, r in sub.iterrows():
        i, j = regimes.index(r["regime"]), confs.index(r["configuration"])
        grid[i, j] = np.log2(r["speedup"])
        sig[i, j] = r["ci_low"] > 1 or r["ci_high"] < 1
    lim = max(1.0, float(np.nanmax(np.abs(grid)))) if np.isfinite(grid).any() else 1.0
    fig, ax = plt.subplots(figsize=(1.3 * len(confs) + 3.5, 0.38 * len(regimes) + 2.0))
    image = ax.imshow(grid, cmap="RdBu", vmin=-lim, vmax=lim, aspect="auto")
    for i in range(len(regimes)):
        for j in range(len(confs)):
            if np.isfinite(grid[i, j]):
                text = f"{2 ** grid[i, j]:.2f}{'*' if sig[i, j] else ''}"
                ax.text(j, i, text, ha="center", va="center", fontsize=7)
    ax.set_xticks(range(len(confs)), [label(c) for c in confs], rotation=30, ha="right", fontsize=7)
    ax.set_yticks(range(len(regimes)), regimes, fontsize=7)
    bar = fig.colorbar(image, ax=ax)
    bar.set_label("log2 speed-up over RRT* (blue: faster)")
    ax.set_title(
        f"Time speed-up over RRT*, {stop_name(stop, eps)} (eps {eps:g}); "
        f"* = {level_name(settings['level'])} CI excludes 1",
        fontsize=9,
    )
    fig.tight_layout()
    return fig


def save_quality(out_png: str | Path, curves, networks, settings: dict) -> None:
    """:func:`quality_figure` saved as a PNG."""
    save_figure(quality_figure(curves, networks, settings), out_png)


def save_regime(out_png: str | Path, cells, stop: str, settings: dict) -> None:
    """:func:`regime_figure` saved as a PNG."""
    save_figure(regime_figure(cells, stop, settings), out_png)
