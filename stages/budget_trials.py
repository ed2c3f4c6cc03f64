"""DVC stage budget_trials@<steps>-<seed>: planner trials on one budget's heatmaps."""

import _interpreter  # noqa: F401  (the venv's python: stages/_interpreter.py)
from vnrrt.cli.stage import stage_main
from vnrrt.pipeline.training_budget import run_budget_trials

if __name__ == "__main__":
    stage_main("budget_trials", run_budget_trials, __doc__, "steps", int, "budget.steps entry",
               more=(("seed", int, "training seed (budget.seeds)"),))  # fmt: skip
