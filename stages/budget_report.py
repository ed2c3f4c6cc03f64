"""DVC stage budget_report@training_budget: the budget curve's statistics, report, figures."""

import _interpreter  # noqa: F401  (the venv's python: stages/_interpreter.py)
from vnrrt.cli.stage import stage_main
from vnrrt.pipeline.training_budget import run_budget_report

if __name__ == "__main__":
    stage_main("budget_report", run_budget_report, __doc__, "name", str, "budget.report entry")
