"""Shared drawing pieces: saving figures atomically, floor maps and probability maps."""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import matplotlib.text
import numpy as np
from matplotlib.colors import ListedColormap, PowerNorm
from matplotlib.ticker import FuncFormatter, LogLocator, NullFormatter

from vnrrt.infra.io import atomic_write_bytes

OBSTACLES = ListedColormap([(0, 0, 0, 0), (0, 0, 0, 1)])  # free transparent, obstacle black
HEAT_CMAP = "Blues"  # white (0) to dark blue (1): start (green) and goal (red) stay visible
HEAT_NORM_GAMMA = 0.5  # a square-root colour scale, so that faint probabilities show


def figure_text(fig) -> str:
    """Every text a reader sees on ``fig`` (suptitle, titles, axis labels, tick labels,
    legends, annotations, colour bar labels), one per line, in drawing order."""
    fig.canvas.draw()  # tick labels exist only once drawn
    found = [t.get_text() for t in fig.findobj(matplotlib.text.Text)]
    return "\n".join(dict.fromkeys(t for t in found if t.strip()))


def save_figure(fig, out_png: str | Path, dpi: int = 110) -> None:
    """Save ``fig`` as PNG atomically (temp file + rename) and close it. The PNG carries
    :func:`figure_text` as its ``Description`` (a tEXt chunk), so that tests and readers can
    check what a figure says without reading pixels."""
    meta = {"Description": figure_text(fig)}
    atomic_write_bytes(
        Path(out_png),
        lambda f: fig.savefig(f, format="png", dpi=dpi, bbox_inches="tight", metadata=meta),
    )
    plt.close(fig)


def rgb_image(fig, dpi: int = 90) -> np.ndarray:
    """``fig`` drawn as an (H, W, 3) uint8 RGB array (for MLflow's step images)."""
    fig.set_dpi(dpi)
    fig.canvas.draw()
    return np.asarray(fig.canvas.buffer_rgba())[..., :3].copy()


def close(fig) -> None:
    """Release a figure made here (after logging it elsewhere, e.g. to MLflow)."""
    plt.close(fig)


def frame_axes(ax, shape: tuple[int, int], title: str) -> None:
    h, w = shape
    ax.set_xlim(0, w)
    ax.set_ylim(h, 0)
    ax.set_xticks([])
    ax.set_yticks([])
    ax.set_title(title, fontsize=9)


def draw_obstacles(ax, grid) -> None:
    """Obstacle cells of an ``(H, W)`` grid in black over whatever is drawn below."""
    h, w = np.shape(grid)
    ax.imshow(
        np.asarray(grid) != 0,
        cmap=OBSTACLES,
        vmin=0,
        vmax=1,
        extent=(0, w, h, 0),
        interpolation="nearest",
    )


def mark_endpoints(ax, start=None, goal=None, centres: bool = True) -> None:
    """Start (green star) and goal (red cross); ``centres`` shifts cells to their centres."""
    shift = 0.5 if centres else 0.0
    if start is not None:
        ax.plot(
            start[0] + shift,
            start[1] + shift,
            "*",
            color="tab:green",
            ms=12,
            mec="white",
            mew=0.6,
            label="start",
        )
    if goal is not None:
        ax.plot(
            goal[0] + shift, goal[1] + shift, "x", color="tab:red", ms=10, mew=2.5, label="goal"
        )


def plot_floor_map(ax, grid, path=None, vertices=None, start=None, goal=None, title=""):
    """Draw an ``(H, W)`` occupancy grid on ``ax`` with an optional optimal ``path``
    ``(T, 2)`` and ``vertices`` ``(K, 2)`` (cells x, y, drawn at cell centres) and the
    start/goal cells."""
    draw_obstacles(ax, grid)
    if path is not None:
        c = np.asarray(path) + 0.5
        ax.plot(c[:, 0], c[:, 1], "-", color="tab:blue", lw=1.2, label="optimal path")
    if vertices is not None:
        c = np.asarray(vertices) + 0.5
        ax.plot(c[:, 0], c[:, 1], "o", color="tab:blue", ms=3.5, label="vertices")
    mark_endpoints(ax, start, goal)
    frame_axes(ax, np.shape(grid), title)


def plot_heatmap(ax, heatmap, grid=None, start=None, goal=None, title="", vmax: float = 1.0):
    """A probability map ``(H, W)`` on the shared colour scale ``[0, vmax]`` (dark = high,
    the paper's Fig. 3 convention), obstacles black, start and goal marked. Returns the
    image, for a colour bar."""
    h, w = np.shape(heatmap)
    image = ax.imshow(
        heatmap,
        cmap=HEAT_CMAP,
        norm=PowerNorm(HEAT_NORM_GAMMA, 0.0, vmax),
        extent=(0, w, h, 0),
        interpolation="nearest",
    )
    if grid is not None:
        draw_obstacles(ax, grid)
    mark_endpoints(ax, start, goal)
    frame_axes(ax, (h, w), title)
    return image


def log_ticks(axis) -> None:
    """A log scale on ``axis`` (an x or y axis, after plotting) with plain-number labels that
    always shows some: powers of ten when the data span 1.5 decades or more, 1-2-5 steps down
    to half a decade, every integer multiple below (a narrow span may hold no power of ten)."""
    getattr(axis.axes, f"set_{axis.axis_name}scale")("log")
    lo, hi = sorted(axis.get_data_interval())
    decades = float(np.log10(hi / lo)) if 0 < lo <= hi < np.inf else 2.0  # unknown: wide
    subs = (1.0,) if decades >= 1.5 else (1.0, 2.0, 5.0) if decades >= 0.5 else range(1, 10)
    axis.set_major_locator(LogLocator(base=10, subs=subs, numticks=6))
    axis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g}"))
    axis.set_minor_formatter(NullFormatter())
