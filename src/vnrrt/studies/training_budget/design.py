"""What the budget curve's trials run, per budget (stage ``budget_trials@<steps>-<seed>``):
RRT* and every learned planner of ``eval.planners`` sampling its ``eval.sources`` network,
M-VNRRT* at the claims' threshold ``planner.tau`` only, not informed, on the random instances
of the instances file (the comparable map set, which the curve reads) and, at the largest
budget only, the named maps (the paper's named-map claims, read over the training seeds
there), every stop rule of the protocol with its trial counts (``eval.named_initial``,
``eval.named_optimal``, ``eval.random_initial``, ``eval.random_optimal``,
``eval.any_angle``), its obstacle rule (``eval.zero_obstacles``) and its paired seeds, so
that a budget's configurations are compared on the same trials, and the budgets and
training seeds on the same instances and seeds.
"""

from __future__ import annotations

from dataclasses import dataclass

from vnrrt.evaluation.config import Configurations, EvalConfig
from vnrrt.evaluation.keys import ConfigKey
from vnrrt.evaluation.protocol import TrialJob, configurations, trial_counts, trial_jobs

BASELINE = ConfigKey("rrt_star")
CONTROL = "nrrt_star"  # the planner the VNRRT* ratio is taken against


def runs_named_maps(steps: int, budgets: list[int]) -> bool:
    """Whether the budget of ``steps`` (one of ``budgets``, ``budget.steps``) also runs the
    named maps: only the largest does (its trials read the paper's claims over the seeds)."""
    return int(steps) == max(int(b) for b in budgets)


@dataclass(frozen=True)
class BudgetTrials:
    """The ``eval`` keys the budget trials read (module doc)."""

    planners: list[str]
    sources: dict[str, str]
    named_initial: int
    named_optimal: int
    random_initial: int
    random_optimal: int
    any_angle: bool
    endpoint_radius: float
    zero_obstacles: bool
    cap_factor: float  # a run's wall-clock cap, x planner.max_seconds (eval.cap_factor)

    def keys(self, tau: float) -> list[ConfigKey]:
        """The configurations, in the protocol's order (``rrt_star``, ``nrrt_star``,
        ``vnrrt_star``, ``m_vnrrt_star@<tau>`` as configured)."""
        ev = Configurations(list(self.planners), dict(self.sources), informed=False,
                            mask_variants=[], masked_controls=False,
                            endpoint_radius=self.endpoint_radius,
                            zero_obstacles=self.zero_obstacles,
                            cap_factor=self.cap_factor)  # fmt: skip
        return configurations(ev, [tau], tau)

    def counts(self, *, named: bool) -> dict[tuple[str, str], int]:
        """Trials per instance for each (instance kind, stop rule), as the protocol's; none on
        the named maps unless ``named`` (the largest budget)."""
        ev = EvalConfig(named_initial=self.named_initial if named else 0,
                        named_optimal=self.named_optimal if named else 0,
                        random_initial=self.random_initial, random_optimal=self.random_optimal,
                        any_angle=self.any_angle)  # fmt: skip
        return trial_counts(ev)

    def jobs(self, kinds: list[str], tau: float, *, named: bool) -> list[TrialJob]:
        """Every job in canonical order; ``kinds[i]``: instance ``i``'s kind (``named`` or
        ``random``) in the instances file; the named maps' only when ``named``."""
        return trial_jobs(kinds, self.keys(tau), self.counts(named=named))

    def stops(self) -> list[str]:
        """The stop rules the curve reads (those run on the random maps), in the protocol's
        order."""
        return list(dict.fromkeys(stop for (_, stop), n in self.counts(named=False).items() if n))

    def ratio_keys(self, tau: float) -> list[ConfigKey]:
        """The planners compared with NRRT* (:data:`CONTROL`): VNRRT* and M-VNRRT*."""
        return [k for k in self.keys(tau) if k.planner not in (BASELINE.planner, CONTROL)]
