"""Optimal grid paths (A*, distance fields), exact any-angle shortest paths and the paper's
vertex (turning point) labels."""

from vnrrt.search.anyangle import (
    any_angle_length,
    any_angle_path,
    convex_corners,
    segment_visible,
)
from vnrrt.search.astar import (
    NoPathError,
    astar,
    descend,
    distance_field,
    move_masks,
    moves_to_path,
    path_length,
)
from vnrrt.search.vertices import path_mask, path_vertices, vertex_indices

__all__ = [
    "NoPathError",
    "any_angle_length",
    "any_angle_path",
    "astar",
    "convex_corners",
    "descend",
    "distance_field",
    "move_masks",
    "moves_to_path",
    "path_length",
    "path_mask",
    "path_vertices",
    "segment_visible",
    "vertex_indices",
]
