"""DVC stage budget_trials@<steps>: planner trials on one budget's heatmaps."""

from vnrrt.evaluation.training_budget.stage import run_budget_trials
from vnrrt.stage_cli import stage_main

if __name__ == "__main__":
    stage_main("budget_trials", run_budget_trials, __doc__, "steps", int, "budget.steps entry")
