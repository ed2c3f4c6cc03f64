"""The training budgets of the budget curve (``conf/budget``; issue 24): which budgets, and
the trainer settings that make a training of ``steps`` optimizer steps a complete run of its
own rather than a cut longer one.

A budget of ``N`` steps keeps the scale's ``trainer.max_epochs`` ``E`` and sets
``trainer.limit_train_batches`` to ``N / E`` (``N`` must be a multiple of ``E``), so the
one-cycle learning-rate schedule (``train.module.scheduler``, ``total_steps`` from the
trainer's estimated stepping batches) is sized to exactly ``N`` steps and ends at its final
value, every epoch ends with validation, and the budget of the scale's own step count is the
pipeline's training itself (same settings, same fingerprint). Nothing here imports torch.
"""

from __future__ import annotations

import copy
from dataclasses import dataclass

from vnrrt.config import check, conf_defaults

REPORT = "training_budget"  # the one name of stage budget_report@<name> (budget.report)


@dataclass
@conf_defaults("budget")
class BudgetConfig:
    """The ``budget`` section: ``steps``, the budgets (optimizer steps, ascending);
    ``seeds``, the training seeds (``train.seed``) at which both networks are trained for
    every budget (ascending); and ``report``, ``[training_budget]`` where there are budgets
    and ``[]`` where there are none (DVC makes no report stage of a matrix over ``[]``)."""

    steps: list[int]
    seeds: list[int]
    report: list[str]

    def validate(self) -> None:
        steps, seeds = self.steps, self.seeds
        ok = all(isinstance(s, int) and s >= 1 for s in steps) and steps == sorted(set(steps))
        check(ok, "budget.steps", steps, "distinct positive integers, ascending")
        ok = all(isinstance(s, int) and s >= 0 for s in seeds) and seeds == sorted(set(seeds))
        check(ok and bool(seeds), "budget.seeds", seeds,
              "distinct non-negative integers, ascending, at least one")  # fmt: skip
        want = [REPORT] if steps else []
        check(self.report == want, "budget.report", self.report,
              f"must be {want} where budget.steps is {steps}")  # fmt: skip


def batches_per_epoch(steps: int, max_epochs: int) -> int:
    """``trainer.limit_train_batches`` of a budget of ``steps`` optimizer steps over
    ``max_epochs`` epochs; :class:`~vnrrt.config.ConfigError` unless it divides evenly."""
    ok = max_epochs >= 1 and steps >= 1 and steps % max_epochs == 0
    check(ok, "budget.steps", steps,
          f"each budget must be a multiple of trainer.max_epochs={max_epochs} (its schedule "
          f"runs max_epochs epochs of steps / max_epochs batches)")  # fmt: skip
    return steps // max_epochs


def budget_config(cfg, steps: int, seed: int):
    """A copy of a training stage's config ``cfg`` (a ``DictConfig``) training for ``steps``
    optimizer steps (module doc) at training seed ``seed`` (``train.seed``)."""
    out = copy.deepcopy(cfg)
    out.trainer.limit_train_batches = batches_per_epoch(int(steps), int(cfg.trainer.max_epochs))
    out.train.seed = int(seed)
    return out


def check_steps(done: int, steps: int, batches: int) -> None:
    """Raise ``ValueError`` unless a budget training ended at step ``steps``."""
    if done != steps:
        raise ValueError(
            f"the budget of {steps} steps ended at step {done}: trainer.max_time was reached, "
            f"or the train split holds fewer than {batches} batches per epoch"
        )


def budget_record(trainer, steps: int) -> dict:
    """What a budget training adds to its metrics: its steps, epochs and batches per epoch,
    and how far its learning-rate schedule ran (``schedule_steps`` of ``schedule_total``:
    equal for a schedule of its own run to its end); ``ValueError`` unless it ran exactly
    ``steps`` steps."""
    batches = int(trainer.limit_train_batches)
    check_steps(int(trainer.global_step), steps, batches)
    configs = trainer.lr_scheduler_configs
    scheduler = configs[0].scheduler if configs else None
    total = getattr(scheduler, "total_steps", None)
    return {"steps": steps, "epochs": int(trainer.current_epoch), "batches_per_epoch": batches,
            "schedule_steps": None if scheduler is None else int(scheduler.last_epoch),
            "schedule_total": None if total is None else int(total)}  # fmt: skip
