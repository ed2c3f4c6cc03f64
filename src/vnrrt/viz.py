"""Every figure of vnrrt (matplotlib, Agg; no pyplot global state).

Coordinates follow :mod:`vnrrt.grid`: images are drawn with ``origin='upper'`` and
``extent=(0, W, H, 0)`` so that a continuous point ``(x, y)`` is plotted at ``(x, y)``
and cell ``(x, y)`` covers ``[x, x+1) x [y, y+1)``.
"""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")

import numpy as np  # noqa: E402
from matplotlib.axes import Axes  # noqa: E402
from matplotlib.collections import LineCollection  # noqa: E402
from matplotlib.figure import Figure  # noqa: E402


def draw_grid(ax: Axes, grid: np.ndarray) -> None:
    """Occupancy ``(H, W)`` (nonzero = obstacle) in black on white, in pixel coordinates."""
    h, w = grid.shape
    ax.imshow(np.asarray(grid) != 0, cmap="gray_r", vmin=0, vmax=1.6, extent=(0, w, h, 0),
              interpolation="nearest")  # fmt: skip
    ax.set_xlim(0, w)
    ax.set_ylim(h, 0)
    ax.set_aspect("equal")


def draw_heatmap(ax: Axes, heatmap: np.ndarray, alpha: float = 0.55) -> None:
    """Sampling heatmap ``(H, W)`` overlaid in a warm colormap (zeros transparent)."""
    h, w = heatmap.shape
    hm = np.ma.masked_less_equal(np.asarray(heatmap, dtype=float), 0.0)
    ax.imshow(hm, cmap="autumn_r", alpha=alpha, extent=(0, w, h, 0), interpolation="nearest")


def draw_tree(ax: Axes, points: np.ndarray, parents: np.ndarray, color: str = "tab:blue") -> None:
    """Tree edges: ``points`` ``(N, 2)`` (x, y), ``parents`` ``(N,)`` (-1 for the root)."""
    child = np.flatnonzero(parents >= 0)
    segs = np.stack([points[parents[child]], points[child]], axis=1)
    ax.add_collection(LineCollection(segs, colors=color, linewidths=0.4, alpha=0.6))


def draw_path(ax: Axes, path: np.ndarray, start, goal, color: str = "red") -> None:
    """Polyline ``path`` ``(K, 2)`` (x, y) with start (green) and goal (blue) markers."""
    if len(path):
        ax.plot(path[:, 0], path[:, 1], color=color, linewidth=1.8)
    ax.plot(*start, "o", color="limegreen", markersize=7, markeredgecolor="black")
    ax.plot(*goal, "*", color="deepskyblue", markersize=11, markeredgecolor="black")


def plan_figure(grid, result, start, goal, heatmap=None, title: str | None = None) -> Figure:
    """Map, heatmap (if any), tree (if the result kept it) and path of one planner result."""
    fig = Figure(figsize=(6, 6), dpi=120)
    ax = fig.add_subplot()
    draw_grid(ax, grid)
    if heatmap is not None:
        draw_heatmap(ax, heatmap)
    if result.tree_points is not None:
        draw_tree(ax, result.tree_points, result.tree_parents)
    draw_path(ax, result.path, start, goal)
    ax.set_title(title or f"{result.planner}: cost {result.cost:.1f} px, {result.iterations} it")
    fig.tight_layout()
    return fig


def cost_trace_figure(results, labels=None) -> Figure:
    """Best cost (px) versus iteration for several results' sparse traces."""
    fig = Figure(figsize=(6, 4), dpi=120)
    ax = fig.add_subplot()
    for i, r in enumerate(results):
        label = labels[i] if labels else r.planner
        ax.step(r.trace_iterations, r.trace_costs, where="post", label=label)
    ax.set_xlabel("iteration")
    ax.set_ylabel("best path cost (px)")
    ax.legend()
    fig.tight_layout()
    return fig


def save(fig: Figure, path: str | Path) -> Path:
    """Write ``fig`` to ``path`` (format from the suffix), creating parent folders."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path)
    return path
