"""DVC stage budget_trials@<steps>: planner trials on one budget's heatmaps."""

import _interpreter  # noqa: F401  (the venv's python: stages/_interpreter.py)
from vnrrt.evaluation.training_budget.stage import run_budget_trials
from vnrrt.stage_cli import stage_main

if __name__ == "__main__":
    stage_main("budget_trials", run_budget_trials, __doc__, "steps", int, "budget.steps entry")
