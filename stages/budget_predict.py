"""DVC stage budget_predict@<steps>: heatmaps and heatmap metrics of one budget's networks."""

import _interpreter  # noqa: F401  (the venv's python: stages/_interpreter.py)
from vnrrt.predict.stage import run_budget_predict
from vnrrt.stage_cli import stage_main

if __name__ == "__main__":
    stage_main("budget_predict", run_budget_predict, __doc__, "steps", int, "budget.steps entry")
