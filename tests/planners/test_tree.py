"""The tree's arrays (planners/tree.py): a finished run's path, segment lengths and trace."""

import numpy as np

from vnrrt.planners import polyline_length
from vnrrt.planners import tree as nodes


def test_a_finished_tree_gives_its_branch_segment_lengths_and_trace():
    """tree.finish on a hand-made tree: root (0, 0) -> (3, 4) -> goal (3, 10); the final cost
    is appended to the trace only when it is not the last point traced."""
    links = np.full((4, 4), -1, np.int64)
    links[1, nodes.PARENT], links[2, nodes.PARENT] = 0, 1
    pts = np.array([[0.0, 0.0], [3.0, 4.0], [3.0, 10.0], [9.0, 9.0]])
    cost = np.array([0.0, 5.0, 11.0, 99.0])
    iters, costs = np.array([7, 0, 0], np.int64), np.array([12.0, 0.0, 0.0])
    path, segs, trace_it, trace_cost = nodes.finish(links, pts, cost, 2, iters, costs, 1, 30)
    assert np.array_equal(path, pts[:3]) and path.dtype == np.float64
    assert segs.tolist() == [5.0, 6.0] and float(np.add.reduce(segs)) == polyline_length(path)
    assert trace_it.tolist() == [7, 30] and trace_cost.tolist() == [12.0, 11.0]
    costs[0] = 11.0  # the final cost already traced: nothing appended
    _, _, trace_it, trace_cost = nodes.finish(links, pts, cost, 2, iters, costs, 1, 30)
    assert trace_it.tolist() == [7] and trace_cost.tolist() == [11.0]
    path, segs, trace_it, trace_cost = nodes.finish(links, pts, cost, -1, iters, costs, 0, 30)
    assert path.shape == (0, 2) and segs.size == 0 and trace_it.size == trace_cost.size == 0
