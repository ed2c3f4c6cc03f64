"""The per-epoch validation figure of a training run (logged to MLflow)."""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np

from vnrrt.viz.common import plot_heatmap


def prediction_figure(rgb, target, vertices, probs, titles=None):
    """Validation figure: one row per instance with the input image ``rgb`` ``(K, H, W, 3)``,
    the ground truth ``target`` ``(K, H, W)`` (true vertices ``(K, H, W)`` ringed) and the
    predicted probability map ``probs`` ``(K, H, W)`` with its colour bar. Returns the figure
    (not saved)."""
    k = len(rgb)
    fig, axes = plt.subplots(k, 3, figsize=(8.0, 2.6 * k), squeeze=False)
    for i in range(k):
        h, w = target[i].shape
        axes[i, 0].imshow(rgb[i], extent=(0, w, h, 0), interpolation="nearest")
        axes[i, 0].set_title(titles[i] if titles else "input", fontsize=8)
        axes[i, 1].imshow(rgb[i], alpha=0.3, extent=(0, w, h, 0), interpolation="nearest")
        shown = np.ma.masked_equal(np.asarray(target[i], dtype=float), 0.0)
        axes[i, 1].imshow(
            shown, cmap="gray_r", vmin=0.0, vmax=1.0, extent=(0, w, h, 0), interpolation="nearest"
        )
        axes[i, 1].set_title("ground truth", fontsize=8)
        ys, xs = np.nonzero(vertices[i])
        axes[i, 1].plot(xs + 0.5, ys + 0.5, "o", mfc="none", mec="tab:orange", ms=6)
        image = plot_heatmap(axes[i, 2], probs[i], title=f"predicted (max {np.max(probs[i]):.2f})")
        fig.colorbar(image, ax=axes[i, 2], fraction=0.046, pad=0.04)
        for ax in axes[i, :2]:
            ax.set_xticks([])
            ax.set_yticks([])
    fig.tight_layout()
    return fig
