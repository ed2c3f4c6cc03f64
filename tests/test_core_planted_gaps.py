"""Three gaps where a planted bug in the core survived the other tests: the vertex rule's
goal end, ``Shard.instances()`` without a split, and shard offsets that decrease while
their first and last entries stay right."""

import zipfile

import numpy as np
import pytest

from vnrrt.data.build import build_shard
from vnrrt.data.config import LabelsConfig
from vnrrt.data.reader import Shard
from vnrrt.data.shards import ShardError, read_arrays, shard_file
from vnrrt.maps.config import DataConfig
from vnrrt.search import path_vertices
from vnrrt.search.vertices import vertex_indices


def _walk(start, moves) -> np.ndarray:
    """Cells ``(T+1, 2)`` (x, y) of a walk from ``start`` by unit ``moves``."""
    return np.cumsum(np.vstack([start, moves]), axis=0)


def test_a_turn_three_steps_before_the_goal_is_a_vertex():
    # 6 steps east, then 3 south: the turn at step 6 has whole windows k = 1, 2, 3 (its
    # outgoing window of k = 3 ends exactly at the goal), so it is a vertex.
    path = _walk([0, 0], [[1, 0]] * 6 + [[0, 1]] * 3)
    assert vertex_indices(path).tolist() == [0, 6, 9]
    assert path_vertices(path).tolist() == [[0, 0], [6, 0], [6, 3]]
    # and mirrored at the start: 3 east, then 6 south
    assert vertex_indices(_walk([0, 0], [[1, 0]] * 3 + [[0, 1]] * 6)).tolist() == [0, 3, 9]


def test_a_turn_two_steps_before_the_goal_is_not_an_interior_vertex():
    # the k = 3 window would pass the goal: only the endpoints (module doc of vertices)
    assert vertex_indices(_walk([0, 0], [[1, 0]] * 6 + [[0, 1]] * 2)).tolist() == [0, 8]


@pytest.fixture(scope="module")
def shard(tmp_path_factory):
    out = tmp_path_factory.mktemp("shard")
    build_shard(shard_file(out, 0), 0, 0, 2, DataConfig(), LabelsConfig(), workers=1)
    return Shard(shard_file(out, 0))


def test_instances_without_a_split_are_every_instance_once(shard):
    everything = shard.instances()
    assert len(everything) == len(shard.arrays["inst_map"]) == len(shard.arrays["inst_length"])
    both = np.sort(np.concatenate([shard.instances("train"), shard.instances("test")]))
    assert np.array_equal(everything, both)
    assert everything[-1] == len(shard.arrays["inst_start"]) - 1


def _rewrite(src, dst, **replace):
    arrays = dict(read_arrays(src)) | replace
    with zipfile.ZipFile(dst, "w") as zf:
        for name, arr in arrays.items():
            with zf.open(f"{name}.npy", "w") as f:
                np.lib.format.write_array(f, np.asarray(arr))
    return dst


@pytest.mark.parametrize("field", ["path_offsets", "vertex_offsets"])
def test_offsets_that_decrease_inside_are_rejected(shard, tmp_path, field):
    offs = read_arrays(shard.file)[field].copy()
    assert offs[0] == 0 and offs[2] > offs[1]
    offs[1], offs[2] = offs[2], offs[1]  # first and last unchanged, one step back inside
    bad = _rewrite(shard.file, tmp_path / "bad.npz", **{field: offs})
    with pytest.raises(ShardError, match=f"bad.npz.*{field}"):
        Shard(bad)
