"""The instances file format: the evaluation instances and everything the protocol needs to
know about them, written once by stage ``instances``
(:func:`vnrrt.evaluation.instances.build_instances`) and read by prediction, oracles and
trials.

Instance ``i`` of the protocol is named map ``i`` for ``i < n_named`` (``map_1`` ..
``map_5``), else evaluation instance ``i - n_named`` of the test split (``random``:
:func:`vnrrt.data.splits.evaluation_keys`, evenly spaced over the test maps). Start and goal
are the centres of the instance's cells, as in the paper. Per instance the file keeps the
A* optimum (8-connected octile length between the cells, the paper's reference), the exact
continuous optimum among closed obstacle cells with its turning points
(:func:`vnrrt.search.any_angle_path`), the taut A* length (the greedy approximation the
exact optimum replaced, kept for comparison), the A* path and its vertices (the labels).

File (``.npz``, format version :data:`FORMAT_VERSION`; ``N`` instances, ``S`` map size):

=================  ================  =====================================================
field              shape, dtype      meaning
=================  ================  =====================================================
``format_version`` (), int64         :data:`FORMAT_VERSION`
``meta``           (), str           JSON: map size, named map names, shard ids
``keys``           (N, 2) int64      (shard id, instance index); named maps (-1, i)
``map_set``        (N,) str          ``map_1`` .. ``map_5`` | ``random``
``name``           (N,) str          named map name | ``map<id>/inst<i>``
``cluster``        (N,) int64        base map id (named map i: -1 - i)
``grids``          (N, S, ceil(S/8)) occupancy bits (``np.packbits`` along x)
``start``          (N, 2) int64      start cell (x, y)
``goal``           (N, 2) int64      goal cell (x, y)
``astar_length``   (N,) float64      A* optimum (px)
``exact_length``   (N,) float64      exact continuous optimum (px)
``taut_length``    (N,) float64      taut A* path (px), >= exact
``path_offsets``   (N+1,) int64      A* path i: ``path_moves[o[i]:o[i+1]]``
``path_moves``     (P,) uint8        chain codes (:data:`vnrrt.grid.MOVES`)
``vertex_offsets`` (N+1,) int64      vertices of path i: ``vertex_steps[o[i]:o[i+1]]``
``vertex_steps``   (V,) uint32       vertex indices into the path's cells
``exact_offsets``  (N+1,) int64      exact path i: ``exact_points[o[i]:o[i+1]]``
``exact_points``   (Q, 2) float64    turning points (x, y), start and goal included
=================  ================  =====================================================
"""

from __future__ import annotations

import dataclasses
import functools
import json
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from vnrrt.infra.io import load_npz
from vnrrt.search.astar import moves_to_path

FORMAT_VERSION = 1


class InstancesError(ValueError):
    """The instances file is missing, malformed or does not fit; the message names it."""


@dataclass(frozen=True)
class EvalInstance:
    """One planning problem of the protocol.

    ``grid`` (H, W) uint8 (1 = obstacle); ``start``/``goal`` continuous points (x, y), the
    centres of the cells ``start_cell``/``goal_cell``; lengths in pixels; ``path`` (T+1, 2)
    and ``vertices`` (K, 2) int64 cells of the A* label; ``exact_path`` (Q, 2) float64
    turning points of the exact optimum; ``heatmaps`` source name -> (H, W) float32.
    """

    index: int
    key: tuple[int, int]
    map_set: str
    map: str
    cluster: int
    grid: np.ndarray
    start_cell: tuple[int, int]
    goal_cell: tuple[int, int]
    astar_length: float
    exact_length: float
    taut_length: float
    path: np.ndarray
    vertices: np.ndarray
    exact_path: np.ndarray
    heatmaps: dict[str, np.ndarray] = field(default_factory=dict, repr=False)

    @property
    def start(self) -> tuple[float, float]:
        return (self.start_cell[0] + 0.5, self.start_cell[1] + 0.5)

    @property
    def goal(self) -> tuple[float, float]:
        return (self.goal_cell[0] + 0.5, self.goal_cell[1] + 0.5)

    @property
    def kind(self) -> str:
        """``'named'`` or ``'random'``."""
        return "random" if self.map_set == "random" else "named"

    def reference(self, stop: str) -> float:
        """Reference length of a stop rule: the exact optimum for ``optimal_any_angle``,
        the A* optimum otherwise (the paper's)."""
        return self.exact_length if stop == "optimal_any_angle" else self.astar_length


@functools.lru_cache(maxsize=4)
def _load(path: str, mtime: float) -> dict[str, np.ndarray]:
    arrays = load_npz(path, "instances file", InstancesError)
    if int(arrays.get("format_version", -1)) != FORMAT_VERSION:
        raise InstancesError(f"instances file {path} is not format {FORMAT_VERSION}")
    return arrays


class Instances:
    """A read instances file (module doc); ``Instances(path)[i]`` is an :class:`EvalInstance`
    without heatmaps."""

    def __init__(self, path: str | Path):
        path = Path(path)
        if not path.is_file():
            raise InstancesError(f"instances file {path} does not exist (run `dvc repro`)")
        self.path = path
        self.arrays = _load(str(path), path.stat().st_mtime)
        self.meta = json.loads(str(self.arrays["meta"]))
        self.size = int(self.meta["map_size"])

    def __len__(self) -> int:
        return len(self.arrays["keys"])

    @property
    def keys(self) -> np.ndarray:
        """``(N, 2)`` int64 (shard id, instance index); named maps ``(-1, i)``."""
        return self.arrays["keys"]

    @property
    def kinds(self) -> list[str]:
        """``'named'`` or ``'random'`` for every instance, in protocol order."""
        return ["random" if m == "random" else "named" for m in self.arrays["map_set"]]

    def optima(self) -> dict[str, dict[str, float]]:
        """``{map_set: {"astar", "exact", "taut"}}``: each named map's optimal lengths (px)
        and their means over the random instances (the paper's random column is a mean)."""
        a, out = self.arrays, {}
        for map_set in dict.fromkeys(a["map_set"]):
            sel = a["map_set"] == map_set
            out[str(map_set)] = {
                k: float(np.mean(a[f"{k}_length"][sel])) for k in ("astar", "exact", "taut")
            }
        return out

    def turns(self) -> dict[int, int]:
        """``{instance: turning points}``: the interior vertices of each exact optimum
        (``exact_points`` holds start and goal too)."""
        counts = np.diff(self.arrays["exact_offsets"]) - 2
        return {i: int(c) for i, c in enumerate(counts)}

    def free_cells(self) -> dict[int, int]:
        """``{instance: free cells}`` of each instance's map (its RRT* gamma's area)."""
        grids = self.arrays["grids"]
        occupied = np.unpackbits(grids, axis=-1, count=self.size).reshape(len(grids), -1).sum(1)
        return {i: int(self.size * self.size - o) for i, o in enumerate(occupied)}

    def named(self) -> dict[str, str]:
        """``{map_set: name}`` of the named maps (``map_1``: ``open_room``, ...)."""
        a = self.arrays
        return {str(m): str(n) for m, n in zip(a["map_set"], a["name"]) if m != "random"}

    def _slice(self, name: str, i: int) -> np.ndarray:
        o = self.arrays[f"{name}_offsets"]
        return o[i], o[i + 1]

    def __getitem__(self, i: int) -> EvalInstance:
        a = self.arrays
        if not 0 <= i < len(self):
            raise IndexError(f"instance {i} is not in 0..{len(self) - 1} of {self.path}")
        start, goal = (int(v) for v in a["start"][i]), (int(v) for v in a["goal"][i])
        p0, p1 = self._slice("path", i)
        v0, v1 = self._slice("vertex", i)
        e0, e1 = self._slice("exact", i)
        path = moves_to_path(a["start"][i], a["path_moves"][p0:p1])
        return EvalInstance(
            index=i,
            key=(int(a["keys"][i, 0]), int(a["keys"][i, 1])),
            map_set=str(a["map_set"][i]),
            map=str(a["name"][i]),
            cluster=int(a["cluster"][i]),
            grid=np.unpackbits(a["grids"][i], axis=-1, count=self.size).astype(np.uint8),
            start_cell=tuple(start),
            goal_cell=tuple(goal),
            astar_length=float(a["astar_length"][i]),
            exact_length=float(a["exact_length"][i]),
            taut_length=float(a["taut_length"][i]),
            path=path,
            vertices=path[a["vertex_steps"][v0:v1].astype(np.int64)],
            exact_path=a["exact_points"][e0:e1].copy(),
        )


def load(
    path: str | Path,
    indices,
    networks: list[str],
    heatmaps_dir: str | Path | None = None,
    parts: list[int] | None = None,
) -> tuple[dict[int, EvalInstance], dict[str, str]]:
    """``{index: instance}`` for ``indices`` of the instances file, each with the heatmaps of
    ``networks`` (read from the ``predict@<k>`` part files of ``parts``, which must cover
    exactly the file's instances, in order), and each network's target (``'path'`` or
    ``'interior_vertices'``, from the files' record of what the network was trained on)."""
    inst = Instances(path)
    maps: dict[str, np.ndarray] = {}
    targets: dict[str, str] = {}
    if networks:
        from vnrrt.data.heatmaps import HeatmapError, read_parts

        files = read_parts(heatmaps_dir, parts or [0])
        if not np.array_equal(files["keys"], inst.keys):
            raise HeatmapError(
                f"heatmap parts {parts} in {heatmaps_dir} do not cover the "
                f"instances of {path} in order (re-run `dvc repro`)"
            )
        missing = sorted(set(networks) - set(files["maps"]))
        if missing:
            raise HeatmapError(f"heatmaps in {heatmaps_dir} have no network {missing}")
        maps = {n: files["maps"][n] for n in networks}
        for n in networks:
            kind = files["meta"][0].get("networks", {}).get(n, {}).get("target", {}).get("kind")
            targets[n] = "interior_vertices" if kind == "vertex" else "path"
    out = {}
    for i in indices:
        heat = {n: m[i].astype(np.float32) for n, m in maps.items()}
        out[i] = dataclasses.replace(inst[i], heatmaps=heat)
    return out, targets
