"""Read access to one shard: maps, instances, optimal paths, vertices and their masks."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from vnrrt.data.shards import read_arrays
from vnrrt.search import moves_to_path, path_mask

TRAIN, TEST = 0, 1
SPLITS = {"train": TRAIN, "test": TEST}


class Shard:
    """A loaded shard (format in :mod:`vnrrt.data.shards`). Instances are indexed 0..N-1.

    Cells are ``(x, y)`` int64 (x = column, y = row); grids are ``(S, S)`` uint8 with
    1 = obstacle, indexed ``grid[y, x]``.
    """

    def __init__(self, path: str | Path):
        self.file = Path(path)
        self.arrays = read_arrays(self.file)
        self.meta = json.loads(str(self.arrays["meta"]))
        self.size = int(self.meta["map_size"])

    @property
    def n_maps(self) -> int:
        return len(self.arrays["map_ids"])

    @property
    def n_instances(self) -> int:
        return len(self.arrays["inst_map"])

    def grid(self, map_index: int) -> np.ndarray:
        """Occupancy ``(S, S)`` uint8 of local map ``map_index``."""
        bits = np.unpackbits(self.arrays["maps"][map_index], axis=-1, count=self.size)
        return bits.astype(np.uint8)

    def instances(self, split: str | None = None) -> np.ndarray:
        """Instance indices ``(n,)`` of one split (``'train'``/``'test'``) or all (None)."""
        if split is None:
            return np.arange(self.n_instances)
        if split not in SPLITS:
            raise ValueError(f"unknown split {split!r}; use 'train' or 'test'")
        map_split = self.arrays["split"][self.arrays["inst_map"]]
        return np.flatnonzero(map_split == SPLITS[split])

    def instance(self, i: int) -> dict:
        """Instance ``i``: map index, global map id, start and goal cells, optimal length."""
        m = int(self.arrays["inst_map"][i])
        return {
            "map_index": m,
            "map_id": int(self.arrays["map_ids"][m]),
            "start": self.arrays["inst_start"][i].astype(np.int64),
            "goal": self.arrays["inst_goal"][i].astype(np.int64),
            "length": float(self.arrays["inst_length"][i]),
        }

    def path(self, i: int) -> np.ndarray:
        """Optimal path ``(T+1, 2)`` int64 cells (x, y) of instance ``i``, start to goal."""
        o = self.arrays["path_offsets"]
        moves = self.arrays["path_moves"][o[i] : o[i + 1]]
        return moves_to_path(self.arrays["inst_start"][i].astype(np.int64), moves)

    def vertex_indices(self, i: int) -> np.ndarray:
        """Indices ``(K,)`` int64 of instance ``i``'s vertices along its path."""
        o = self.arrays["vertex_offsets"]
        return self.arrays["vertex_steps"][o[i] : o[i + 1]].astype(np.int64)

    def vertices(self, i: int) -> np.ndarray:
        """Vertices ``(K, 2)`` int64 cells (x, y) of instance ``i`` (start and goal included)."""
        return self.path(i)[self.vertex_indices(i)]

    def path_mask(self, i: int) -> np.ndarray:
        """Boolean ``(S, S)`` mask of instance ``i``'s path cells (NRRT* target)."""
        return path_mask(self.path(i), (self.size, self.size))

    def vertex_mask(self, i: int) -> np.ndarray:
        """Boolean ``(S, S)`` mask of instance ``i``'s vertices (VertexNet target)."""
        return path_mask(self.vertices(i), (self.size, self.size))
