"""DVC stage budget_train@<network>-<steps>-<seed>: one network of the training-budget curve."""

import _interpreter  # noqa: F401  (the venv's python: stages/_interpreter.py)
from vnrrt.cli.stage import stage_main
from vnrrt.pipeline.budget_training import run_budget_train

if __name__ == "__main__":
    stage_main("budget_train", run_budget_train, __doc__, "network", str, "vertexnet or nrrtnet",
               more=(("steps", int, "optimizer steps of the budget (budget.steps)"),
                     ("seed", int, "training seed (budget.seeds)")))  # fmt: skip
