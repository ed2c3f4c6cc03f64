"""The one result type returned by every planner (RRT*, NRRT*, VNRRT*, M-VNRRT*)."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np


@dataclass(frozen=True)
class Milestone:
    """When the best cost first fell to ``bound`` pixels or below (``inf``: any solution).

    ``time`` is in seconds since the planner started and ``iteration`` counts samples;
    both are NaN / -1 when the bound was never reached.
    """

    bound: float
    time: float = float("nan")
    iteration: int = -1

    @property
    def reached(self) -> bool:
        return self.iteration >= 0


@dataclass(frozen=True)
class PlanResult:
    """Outcome of one planner run. Lengths in pixels, times in seconds, points ``(x, y)``.

    Attributes:
        planner: ``'rrt_star'``, ``'nrrt_star'``, ``'vnrrt_star'`` or ``'m_vnrrt_star'``.
        success: the stop rule was met (``initial``: a solution exists; ``optimal``:
            ``cost <= target_cost``). False after a budget was hit.
        stop_reason: ``'solved'``, ``'max_iterations'`` or ``'max_seconds'``.
        path: ``(K, 2)`` float64 best path found, start to goal (``(0, 2)`` if none); it
            is returned even when ``success`` is False.
        cost: polyline length of ``path`` (``inf`` if none).
        iterations: samples drawn. ``tree_size``: nodes, start and goal included.
        collision_checks: segment-versus-grid tests made.
        time_to_first: seconds to the first solution (NaN if none).
        time_to_stop: seconds until the run stopped (success or budget).
        first_cost, first_iteration: cost and iteration of the first solution.
        trace_iterations, trace_costs: ``(T,)`` sparse best-cost-versus-iteration trace
            (a point per relative improvement above 1e-4, and the final value).
        reference_length, target_cost: the stop-rule reference and ``(1 + eps) x`` it
            (None for ``stop='initial'`` without a reference).
        milestones: the extra cost bounds asked for, with the time each was reached.
        fallback_uniform: a heatmap/masked sampler had no positive weight and sampled
            uniformly instead.
        setup_time: seconds spent building the sampler (0 when a prebuilt one was given);
            not part of ``time_to_first`` / ``time_to_stop``.
        budget: the run's ``(max_iterations, max_seconds)`` on its map (the configuration's
            fixed budgets, or those of its budget rule: ``PlannerConfig.budgets``).
        tree_points, tree_parents: ``(N, 2)`` and ``(N,)`` (parent index, -1 for the
            root) when ``keep_tree`` was asked, else None.
    """

    planner: str
    success: bool
    stop_reason: str
    path: np.ndarray
    cost: float
    iterations: int
    tree_size: int
    collision_checks: int
    time_to_first: float
    time_to_stop: float
    first_cost: float
    first_iteration: int
    trace_iterations: np.ndarray
    trace_costs: np.ndarray
    reference_length: float | None = None
    target_cost: float | None = None
    milestones: tuple[Milestone, ...] = ()
    fallback_uniform: bool = False
    setup_time: float = 0.0
    budget: tuple[int, float] | None = None
    tree_points: np.ndarray | None = field(default=None, repr=False)
    tree_parents: np.ndarray | None = field(default=None, repr=False)

    def summary(self) -> str:
        """One line: planner, success, cost, iterations, nodes, times and budget."""
        ref = "" if self.reference_length is None else f" ref={self.reference_length:.2f}"
        budget = "" if self.budget is None else f" budget={self.budget[0]} it/{self.budget[1]:g} s"
        return (
            f"{self.planner}: success={self.success} ({self.stop_reason}) cost={self.cost:.2f}"
            f"{ref} iterations={self.iterations} nodes={self.tree_size} "
            f"checks={self.collision_checks} first={self.time_to_first * 1e3:.2f} ms "
            f"stop={self.time_to_stop * 1e3:.2f} ms{budget}"
        )
