"""Every figure of the project (matplotlib, Agg backend). Nothing else imports matplotlib.

Coordinates as in :mod:`vnrrt.grid`: images are drawn with ``extent=(0, W, H, 0)`` so a
continuous point (x, y) is plotted at x right, y down, and a cell (x, y) at its centre
(x + 0.5, y + 0.5).
"""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

# --- maps and datasets ---------------------------------------------------------------


def plot_floor_map(ax, grid, path=None, vertices=None, start=None, goal=None, title=""):
    """Draw an ``(H, W)`` occupancy grid (obstacles black) on ``ax`` with an optional
    optimal path ``(T, 2)`` and vertices ``(K, 2)`` (cells x, y, drawn at cell centres),
    the start as a green star and the goal as a red cross (the paper's Fig. 4 style)."""
    h, w = grid.shape
    ax.imshow(np.asarray(grid) != 0, cmap="gray_r", extent=(0, w, h, 0), interpolation="nearest")
    if path is not None:
        c = np.asarray(path) + 0.5
        ax.plot(c[:, 0], c[:, 1], "-", color="tab:blue", lw=1.2, label="optimal path")
    if vertices is not None:
        c = np.asarray(vertices) + 0.5
        ax.plot(c[:, 0], c[:, 1], "o", color="tab:orange", ms=3.5, label="vertices")
    if start is not None:
        ax.plot(start[0] + 0.5, start[1] + 0.5, "*", color="tab:green", ms=12)
    if goal is not None:
        ax.plot(goal[0] + 0.5, goal[1] + 0.5, "x", color="tab:red", ms=10, mew=2.5)
    ax.set_xlim(0, w)
    ax.set_ylim(h, 0)
    ax.set_xticks([])
    ax.set_yticks([])
    ax.set_title(title, fontsize=9)


def save_named_maps(shard_path, out_png) -> None:
    """Fig. 4: the five named maps of a named-maps shard with optimal paths and vertices."""
    from vnrrt.data.reader import Shard

    shard = Shard(shard_path)
    names = shard.meta.get("names", [str(i) for i in range(shard.n_maps)])
    fig, axes = plt.subplots(1, shard.n_instances, figsize=(3.2 * shard.n_instances, 3.4))
    for i, ax in enumerate(np.atleast_1d(axes)):
        inst = shard.instance(i)
        title = f"Map {i + 1}: {names[inst['map_index']]}\nA* length {inst['length']:.1f}"
        plot_floor_map(
            ax, shard.grid(inst["map_index"]), shard.path(i), shard.vertices(i),
            inst["start"], inst["goal"], title,
        )  # fmt: skip
    fig.tight_layout()
    save_figure(fig, out_png)


def save_figure(fig, out_png) -> None:
    """Save ``fig`` as PNG atomically (temp file + rename) and close it."""
    from pathlib import Path

    from vnrrt.data.shards import atomic_write_bytes

    atomic_write_bytes(
        Path(out_png), lambda f: fig.savefig(f, format="png", dpi=110, bbox_inches="tight")
    )
    plt.close(fig)


# --- planners --------------------------------------------------------------------------


def plot_plan(ax, grid, result, start, goal, heatmap=None, title=None):
    """Draw one planner result on ``ax``: the ``(H, W)`` grid, the sampling ``heatmap``
    ``(H, W)`` (if any, zeros transparent), the tree (if the result kept it, i.e.
    ``plan(..., keep_tree=True)``), the path ``(K, 2)`` and the continuous start and goal
    points ``(x, y)`` (drawn where they are, not shifted to cell centres)."""
    from matplotlib.collections import LineCollection

    h, w = grid.shape
    ax.imshow(np.asarray(grid) != 0, cmap="gray_r", extent=(0, w, h, 0), interpolation="nearest")
    if heatmap is not None:
        hm = np.ma.masked_less_equal(np.asarray(heatmap, dtype=float), 0.0)
        ax.imshow(hm, cmap="autumn_r", alpha=0.55, extent=(0, w, h, 0), interpolation="nearest")
    if result.tree_points is not None:
        pts, par = result.tree_points, result.tree_parents
        child = np.flatnonzero(par >= 0)
        segs = np.stack([pts[par[child]], pts[child]], axis=1)
        ax.add_collection(LineCollection(segs, colors="tab:blue", linewidths=0.4, alpha=0.6))
    if len(result.path):
        ax.plot(result.path[:, 0], result.path[:, 1], "-", color="tab:red", lw=1.8)
    ax.plot(start[0], start[1], "*", color="tab:green", ms=12)
    ax.plot(goal[0], goal[1], "x", color="tab:red", ms=10, mew=2.5)
    ax.set_xlim(0, w)
    ax.set_ylim(h, 0)
    ax.set_xticks([])
    ax.set_yticks([])
    default = f"{result.planner}: cost {result.cost:.1f} px, {result.iterations} iterations"
    ax.set_title(title or default, fontsize=9)


def save_plan(out_png, grid, result, start, goal, heatmap=None, title=None) -> None:
    """Map, heatmap, tree and path of one planner result (:func:`plot_plan`) as a PNG."""
    fig, ax = plt.subplots(figsize=(6, 6))
    plot_plan(ax, grid, result, start, goal, heatmap, title)
    fig.tight_layout()
    save_figure(fig, out_png)


def plot_cost_traces(ax, results, labels=None):
    """Best path cost (px) versus iteration from the sparse traces of planner results."""
    for i, r in enumerate(results):
        label = labels[i] if labels is not None else r.planner
        ax.step(r.trace_iterations, r.trace_costs, where="post", label=label)
    ax.set_xlabel("iteration")
    ax.set_ylabel("best path cost (px)")
    ax.legend(fontsize=8)


# --- evaluation ------------------------------------------------------------------------


def save_improvements(out_png, improvements, title):
    """Fig. 5: improvement over RRT* (``baseline / planner - 1``, in %) per map set.

    ``improvements``: ``{planner_key: {map_set: (value, ci_low, ci_high)}}``."""
    keys = list(improvements)
    sets = sorted({m for v in improvements.values() for m in v})
    fig, ax = plt.subplots(figsize=(1.6 * len(sets) + 3, 3.8))
    width = 0.8 / max(len(keys), 1)
    for i, key in enumerate(keys):
        vals = np.array([improvements[key].get(m, (np.nan,) * 3) for m in sets]) * 100
        xs = np.arange(len(sets)) + (i - (len(keys) - 1) / 2) * width
        err = np.abs(vals[:, 1:].T - vals[:, 0])
        ax.bar(xs, vals[:, 0], width, yerr=err, capsize=2, label=key)
    ax.axhline(0, color="black", lw=0.8)
    ax.set_xticks(np.arange(len(sets)), sets)
    ax.set_ylabel("improvement over RRT* (%)")
    ax.set_title(title, fontsize=10)
    if keys:
        ax.legend(fontsize=7, ncol=2)
    else:
        ax.text(0.5, 0.5, "no trials for this stop rule", ha="center", transform=ax.transAxes)
    save_figure(fig, out_png)


def save_convergence_table(out_png, curves):
    """Cost versus time per map set: ``curves`` a table with columns ``planner``,
    ``map_set``, ``factor`` (cost bound / A* length; the smallest is the stop rule) and
    ``median_time`` (s) at which the best cost first fell below that bound."""
    sets = sorted(set(curves["map_set"]))
    fig, axes = plt.subplots(1, len(sets), figsize=(3.6 * len(sets), 3.4), squeeze=False)
    for ax, map_set in zip(axes[0], sets):
        sub = curves[curves["map_set"] == map_set]
        for key, rows in sub.groupby("planner"):
            ax.plot(rows["median_time"], rows["factor"], "o-", ms=3, label=key)
        ax.set_xscale("log")
        ax.set_xlabel("median time (s)")
        ax.set_title(map_set, fontsize=9)
    axes[0, 0].set_ylabel("best cost / A* length")
    axes[0, -1].legend(fontsize=7)
    fig.suptitle("Convergence to the optimal path", fontsize=10)
    save_figure(fig, out_png)


# --- training: predicted heatmaps (the paper's Fig. 3) ---------------------------------


def close(fig) -> None:
    """Release a figure made here (after logging it elsewhere, e.g. to MLflow)."""
    plt.close(fig)


def plot_heatmap(ax, heatmap, title="", vmax=None):
    """A probability map ``(H, W)`` on ``ax``, dark = high (the paper's Fig. 3 convention),
    over ``[0, vmax]`` (default: its maximum, so faint maps stay visible)."""
    h, w = heatmap.shape
    top = float(vmax if vmax is not None else max(float(np.max(heatmap)), 1e-6))
    ax.imshow(heatmap, cmap="gray_r", vmin=0.0, vmax=top, extent=(0, w, h, 0),
              interpolation="nearest")  # fmt: skip
    ax.set_xticks([])
    ax.set_yticks([])
    ax.set_title(title, fontsize=8)


def prediction_figure(rgb, target, vertices, probs, titles=None):
    """Validation figure: one row per instance with the input image ``rgb`` ``(K, H, W, 3)``,
    the ground truth ``target`` ``(K, H, W)`` (true vertices ``(K, H, W)`` ringed) and the
    predicted probability map ``probs`` ``(K, H, W)``. Returns the figure (not saved)."""
    k = len(rgb)
    fig, axes = plt.subplots(k, 3, figsize=(7.5, 2.6 * k), squeeze=False)
    for i in range(k):
        h, w = target[i].shape
        axes[i, 0].imshow(rgb[i], extent=(0, w, h, 0), interpolation="nearest")
        axes[i, 0].set_title(titles[i] if titles else "input", fontsize=8)
        axes[i, 1].imshow(rgb[i], alpha=0.3, extent=(0, w, h, 0), interpolation="nearest")
        shown = np.ma.masked_equal(np.asarray(target[i], dtype=float), 0.0)
        axes[i, 1].imshow(shown, cmap="gray_r", vmin=0.0, vmax=1.0, extent=(0, w, h, 0),
                          interpolation="nearest")  # fmt: skip
        axes[i, 1].set_title("ground truth", fontsize=8)
        ys, xs = np.nonzero(vertices[i])
        axes[i, 1].plot(xs + 0.5, ys + 0.5, "o", mfc="none", mec="tab:orange", ms=6)
        plot_heatmap(axes[i, 2], probs[i], f"predicted (max {float(np.max(probs[i])):.2f})")
        for ax in axes[i, :2]:
            ax.set_xticks([])
            ax.set_yticks([])
    fig.tight_layout()
    return fig


def save_heatmaps(out_png, grids, paths, vertices, heatmaps, titles=None) -> None:
    """Fig. 3 for several maps: per row (one instance) (a) the optimal path ``paths[i]``
    ``(T, 2)`` on grid ``grids[i]`` ``(H, W)``, (b) its vertices ``(K, 2)`` (cells x, y), then
    one column per entry of ``heatmaps`` ``{name: (N, H, W)}`` (e.g. NRRT*, VertexNet)."""
    n, cols = len(grids), 2 + len(heatmaps)
    fig, axes = plt.subplots(n, cols, figsize=(2.6 * cols, 2.7 * n), squeeze=False)
    for i in range(n):
        name = titles[i] if titles else f"map {i + 1}"
        plot_floor_map(axes[i, 0], grids[i], path=paths[i], title=f"{name}: optimal path")
        plot_floor_map(axes[i, 1], grids[i], vertices=vertices[i], title="vertices")
        for j, (label, maps) in enumerate(heatmaps.items()):
            plot_heatmap(axes[i, 2 + j], np.asarray(maps[i], dtype=float), label)
    fig.tight_layout()
    save_figure(fig, out_png)
