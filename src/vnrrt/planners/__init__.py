"""RRT*, NRRT*, VNRRT* and M-VNRRT* as one numba RRT* core with pluggable samplers.

Entry points: :func:`plan` and :class:`Planner` (:mod:`.planner`); settings
:class:`PlannerConfig` (:mod:`.config`, from ``conf/planner/``): by default :data:`USER`
(``conf/planner/user.yaml``, budgets scaled with the map's free area); the paper's protocol
:meth:`PlannerConfig.paper` (``conf/planner/default.yaml``). The path of a call:
:func:`plan` builds a :class:`Planner` and solves; :meth:`Planner.solve` checks the query and
makes one timed run (:mod:`.run`), whose tree grows in one compiled call of the RRT* core
(:mod:`.rrt_star`, sampling from :mod:`.samplers`). Depends only on :mod:`vnrrt.grid`,
:mod:`vnrrt.search` and the location of ``conf/``.
"""

from vnrrt.planners.collision import path_free, point_free, polyline_length, segment_free
from vnrrt.planners.config import FASTEST, PLANNERS, USER, PlannerConfig, PlannerConfigError
from vnrrt.planners.planner import Planner, make_sampler, plan, warmup
from vnrrt.planners.reference import astar_length, reference_length, taut_length, taut_path
from vnrrt.planners.result import Milestone, PlanResult
from vnrrt.planners.samplers import Sampler, draw, heatmap_sampler, uniform_sampler
from vnrrt.search import any_angle_length, any_angle_path

__all__ = [
    "FASTEST",
    "PLANNERS",
    "USER",
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
