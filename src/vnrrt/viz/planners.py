"""One planner run: map, sampling heatmap, tree and path; cost traces."""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.collections import LineCollection

from vnrrt.names import PLANNER_NAMES
from vnrrt.viz.common import draw_obstacles, frame_axes, mark_endpoints, save_figure


def plot_plan(ax, grid, result, start, goal, heatmap=None, title=None):
    """Draw one planner result on ``ax``: the ``(H, W)`` grid, the sampling ``heatmap``
    ``(H, W)`` (if any, zeros transparent), the tree (if the result kept it, i.e.
    ``plan(..., keep_tree=True)``), the path ``(K, 2)`` and the continuous start and goal
    points ``(x, y)`` (drawn where they are, not shifted to cell centres)."""
    h, w = grid.shape
    if heatmap is not None:
        hm = np.ma.masked_less_equal(np.asarray(heatmap, dtype=float), 0.0)
        ax.imshow(hm, cmap="autumn_r", alpha=0.55, extent=(0, w, h, 0), interpolation="nearest")
    draw_obstacles(ax, grid)
    if result.tree_points is not None:
        pts, par = result.tree_points, result.tree_parents
        child = np.flatnonzero(par >= 0)
        segs = np.stack([pts[par[child]], pts[child]], axis=1)
        ax.add_collection(LineCollection(segs, colors="tab:blue", linewidths=0.4, alpha=0.6))
    if len(result.path):
        ax.plot(result.path[:, 0], result.path[:, 1], "-", color="tab:red", lw=1.8)
    mark_endpoints(ax, start, goal, centres=False)
    name = PLANNER_NAMES.get(result.planner, result.planner)
    default = f"{name}: cost {result.cost:.1f} px, {result.iterations} iterations"
    frame_axes(ax, (h, w), title or default)


def save_plan(out_png, grid, result, start, goal, heatmap=None, title=None) -> None:
    """Map, heatmap, tree and path of one planner result (:func:`plot_plan`) as a PNG."""
    fig, ax = plt.subplots(figsize=(6, 6))
    plot_plan(ax, grid, result, start, goal, heatmap, title)
    fig.tight_layout()
    save_figure(fig, out_png)


def plot_cost_traces(ax, results, labels=None):
    """Best path cost (px) versus iteration from the sparse traces of planner results."""
    for i, r in enumerate(results):
        label = labels[i] if labels is not None else PLANNER_NAMES.get(r.planner, r.planner)
        ax.step(r.trace_iterations, r.trace_costs, where="post", label=label)
    ax.set_xlabel("iteration")
    ax.set_ylabel("best path cost (px)")
    ax.legend(fontsize=8)
