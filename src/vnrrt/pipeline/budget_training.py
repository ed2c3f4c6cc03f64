"""Entry point of stage ``budget_train@<network>-<steps>-<seed>`` (the budget curve's
trainings; the curve's other stages: :mod:`.training_budget`)."""

from __future__ import annotations

from omegaconf import DictConfig

from vnrrt.config import section
from vnrrt.config.paths import Paths


def run_budget_train(cfg: DictConfig, network: str, steps: int, seed: int) -> dict:
    """Stage ``budget_train@<network>-<steps>-<seed>``: ``network`` trained for ``steps``
    optimizer steps at ``train.seed`` ``seed`` with a schedule of its own
    (:func:`vnrrt.studies.training_budget.budget.budget_config`) ->
    ``paths.budget_training(network, steps, seed)``, resumable as the pipeline's trainings;
    its metrics add ``budget`` (:func:`~vnrrt.studies.training_budget.budget.budget_record`)."""
    from vnrrt.pipeline.training import train_network
    from vnrrt.studies.training_budget.budget import budget_config

    files = section(cfg, "paths", Paths).budget_training(network, steps, seed)
    return train_network(budget_config(cfg, steps, seed), network, files, budget=int(steps))
