"""DVC stage budget_train@<network>-<steps>: one network of the training-budget curve."""

import _interpreter  # noqa: F401  (the venv's python: stages/_interpreter.py)
from vnrrt.cli.stage import stage_main
from vnrrt.pipeline.training_budget import run_budget_train

if __name__ == "__main__":
    stage_main("budget_train", run_budget_train, __doc__, "network", str, "vertexnet or nrrtnet",
               more=(("steps", int, "optimizer steps of the budget (budget.steps)"),))  # fmt: skip
