"""Optimal grid paths (A*, distance fields) and the paper's vertex (turning point) labels."""

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
    "astar",
    "descend",
    "distance_field",
    "move_masks",
    "moves_to_path",
    "path_length",
    "path_mask",
    "path_vertices",
    "vertex_indices",
]
