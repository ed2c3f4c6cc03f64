"""DVC stage budget_predict@<steps>-<seed>: heatmaps and heatmap metrics of one budget's
networks."""

import _interpreter  # noqa: F401  (the venv's python: stages/_interpreter.py)
from vnrrt.cli.stage import stage_main
from vnrrt.pipeline.training_budget import run_budget_predict

if __name__ == "__main__":
    stage_main("budget_predict", run_budget_predict, __doc__, "steps", int, "budget.steps entry",
               more=(("seed", int, "training seed (budget.seeds)"),))  # fmt: skip
