"""RRT*, NRRT*, VNRRT* and M-VNRRT* as one numba RRT* core with pluggable samplers.

Entry point: :func:`plan`. Depends only on :mod:`vnrrt.grid` and :mod:`vnrrt.search`.
"""

from vnrrt.planners.api import Planner, make_sampler, plan, warmup
from vnrrt.planners.collision import path_free, point_free, polyline_length, segment_free
from vnrrt.planners.config import FASTEST, PLANNERS, PlannerConfig, PlannerConfigError
from vnrrt.planners.reference import (
    any_angle_length,
    any_angle_path,
    astar_length,
    reference_length,
    taut_length,
    taut_path,
)
from vnrrt.planners.result import Milestone, PlanResult
from vnrrt.planners.samplers import Sampler, draw, heatmap_sampler, uniform_sampler

__all__ = [
    "FASTEST",
    "PLANNERS",
    "Milestone",
    "PlanResult",
    "Planner",
    "PlannerConfig",
    "PlannerConfigError",
    "Sampler",
    "any_angle_length",
    "any_angle_path",
    "astar_length",
    "draw",
    "heatmap_sampler",
    "make_sampler",
    "path_free",
    "plan",
    "point_free",
    "polyline_length",
    "reference_length",
    "segment_free",
    "taut_length",
    "taut_path",
    "uniform_sampler",
    "warmup",
]
