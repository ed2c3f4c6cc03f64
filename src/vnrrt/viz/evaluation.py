"""Figures of the evaluation: Fig. 3 (heatmaps), Fig. 5 (improvement over RRT*) and the
convergence curves."""

from __future__ import annotations

from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

from vnrrt.evaluation.keys import is_informed, label, sort_texts
from vnrrt.names import MAP_SETS, level_name, map_set_title, stop_name
from vnrrt.viz.common import log_ticks, plot_floor_map, plot_heatmap, save_figure

HEATMAP_TITLES = {"nrrtnet": "(c) NRRT* network", "vertexnet": "(d) VertexNet"}


def heatmaps_figure(grids, paths, vertices, starts, goals, heatmaps: dict, titles=None):
    """Fig. 3 for several instances: per row (a) the optimal path, (b) its vertices, then one
    column per entry of ``heatmaps`` ``{name: (N, H, W)}`` in the paper's order (NRRT*
    network, then VertexNet), on one colour scale with a colour bar. ``grids`` (N, H, W);
    paths, vertices, starts and goals in cells (x, y). Returns the figure."""
    names = sorted(
        heatmaps,
        key=lambda n: (
            n not in HEATMAP_TITLES,
            list(HEATMAP_TITLES).index(n) if n in HEATMAP_TITLES else 0,
            n,
        ),
    )
    n, cols = len(grids), 2 + len(names)
    fig, axes = plt.subplots(
        n, cols, figsize=(2.6 * cols + 0.6, 2.9 * n), squeeze=False, layout="constrained"
    )
    image = None
    for i in range(n):
        row = titles[i] if titles else f"instance {i + 1}"
        plot_floor_map(
            axes[i, 0],
            grids[i],
            path=paths[i],
            start=starts[i],
            goal=goals[i],
            title=f"{row}\n(a) optimal path",
        )
        plot_floor_map(
            axes[i, 1],
            grids[i],
            vertices=vertices[i],
            start=starts[i],
            goal=goals[i],
            title="(b) vertices",
        )
        for j, name in enumerate(names):
            heat = np.asarray(heatmaps[name][i], dtype=float)
            image = plot_heatmap(
                axes[i, 2 + j], heat, grids[i], starts[i], goals[i], HEATMAP_TITLES.get(name, name)
            )
    if image is not None:
        bar = fig.colorbar(image, ax=axes[:, 2:].ravel().tolist(), shrink=0.9, aspect=30)
        bar.set_label("predicted probability (square-root scale)")
    return fig


def save_heatmaps(out_png, *args, **kwargs) -> None:
    """:func:`heatmaps_figure` saved as a PNG."""
    save_figure(heatmaps_figure(*args, **kwargs), out_png)


def improvements_figure(per_key: dict, stop: str, eps: float, level: float, baseline: str = "RRT*"):
    """Fig. 5: improvement over ``baseline`` in % (paired speed-up - 1) per map set, one bar
    per configuration in the paper's order, whiskers = the CI at ``level``; ``eps``: the
    stop tolerance. ``per_key``: ``{key: {map_set: {"speedup", "ci_low", "ci_high"}}}``.
    Returns the figure."""
    keys = sort_texts(k for k in per_key if not is_informed(k))
    sets = [m for m in MAP_SETS if any(m in per_key[k] for k in keys)]
    fig, ax = plt.subplots(figsize=(1.7 * len(sets) + 3, 4.0))
    width = 0.8 / max(len(keys), 1)
    for i, key in enumerate(keys):
        vals = np.array(
            [
                [
                    per_key[key][m][f] if m in per_key[key] else np.nan
                    for f in ("speedup", "ci_low", "ci_high")
                ]
                for m in sets
            ]
        )
        pct = (vals - 1.0) * 100.0
        xs = np.arange(len(sets)) + (i - (len(keys) - 1) / 2) * width
        err = np.abs(pct[:, 1:].T - pct[:, 0])
        ax.bar(xs, pct[:, 0], width, yerr=err, capsize=2, label=label(key))
    ax.axhline(0, color="black", lw=0.8)
    ax.set_xticks(np.arange(len(sets)), [map_set_title(m) for m in sets])
    ax.set_ylabel(f"time improvement over {baseline} (%)")
    ax.set_title(f"Time improvement over {baseline}, {stop_name(stop, eps)}", fontsize=10)
    ax.legend(fontsize=7, ncol=2)
    fig.text(
        0.01,
        -0.04,
        "Bars: geometric mean over instances of median(RRT*) / median(planner)"
        f" - 1; whiskers: {level_name(level)} CI (bootstrap over base maps, then trials).",
        fontsize=7,
    )
    return fig


def save_improvements(out_png, per_key: dict, stop: str, eps: float, level: float) -> None:
    """:func:`improvements_figure` saved as a PNG."""
    save_figure(improvements_figure(per_key, stop, eps, level), out_png)


def convergence_figure(curves, names: dict[str, str] | None = None):
    """Median time (ms, log axis) to reach a cost of ``factor`` x reference, one panel per
    (optimal stop rule, map set), one line per configuration, one shared legend.
    ``curves``: columns stop, planner, map_set, factor, median_time (s). Returns the figure."""
    stops = [s for s in ("optimal", "optimal_any_angle") if s in set(curves["stop"])]
    sets = [m for m in MAP_SETS if m in set(curves["map_set"])]
    fig, axes = plt.subplots(
        len(stops),
        len(sets),
        figsize=(3.0 * len(sets), 2.9 * len(stops)),
        squeeze=False,
        sharey="row",
    )
    handles = {}
    for r, stop in enumerate(stops):
        for c, map_set in enumerate(sets):
            ax = axes[r, c]
            sub = curves[(curves["stop"] == stop) & (curves["map_set"] == map_set)]
            for key in sort_texts(k for k in set(sub["planner"]) if not is_informed(k)):
                rows = sub[sub["planner"] == key].sort_values("factor", ascending=False)
                (line,) = ax.plot(rows["median_time"] * 1e3, rows["factor"], "o-", ms=3)
                handles.setdefault(label(key), line)
            log_ticks(ax.xaxis)
            ax.set_title(map_set_title(map_set, (names or {}).get(map_set)), fontsize=9)
            ax.set_xlabel("median time (ms)", fontsize=8)
            ax.tick_params(labelsize=7)
        reference = "A* length" if stop == "optimal" else "exact optimum"
        axes[r, 0].set_ylabel(f"best cost / {reference}", fontsize=8)
    fig.legend(
        handles.values(),
        handles.keys(),
        loc="lower center",
        ncol=min(len(handles), 6),
        fontsize=8,
        bbox_to_anchor=(0.5, -0.02),
    )
    fig.suptitle("Convergence to the optimal path (median over trials)", fontsize=10)
    fig.tight_layout(rect=(0, 0.06, 1, 1))
    return fig


def save_convergence(out_png: str | Path, curves, names: dict[str, str] | None = None) -> None:
    """:func:`convergence_figure` saved as a PNG."""
    save_figure(convergence_figure(curves, names), out_png)
