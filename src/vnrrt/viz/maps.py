"""Fig. 4: the five named maps with their optimal paths and vertices."""

from __future__ import annotations

from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

from vnrrt.names import map_set_title
from vnrrt.viz.common import plot_floor_map, save_figure


def save_named_maps(shard, out_png: str | Path) -> None:
    """Fig. 4 from the named maps (a :class:`~vnrrt.data.reader.Shard`), saved as a PNG
    (:func:`named_maps_figure`)."""
    save_figure(named_maps_figure(shard), out_png)


def named_maps_figure(shard):
    """Fig. 4 from a named-maps :class:`~vnrrt.data.reader.Shard`: one panel per instance
    with its map, A* path, vertices, start and goal, titled ``Map k: name`` and its A*
    length. Returns the figure."""
    names = shard.meta.get("names", [str(i) for i in range(shard.n_maps)])
    fig, axes = plt.subplots(1, shard.n_instances, figsize=(3.2 * shard.n_instances, 3.5))
    for i, ax in enumerate(np.atleast_1d(axes)):
        inst = shard.instance(i)
        title = f"{map_set_title(f'map_{i + 1}', names[inst['map_index']])}\n"
        title += f"A* length {inst['length']:.1f} px"
        plot_floor_map(
            ax,
            shard.grid(inst["map_index"]),
            shard.path(i),
            shard.vertices(i),
            inst["start"],
            inst["goal"],
            title,
        )
    fig.tight_layout()
    return fig
