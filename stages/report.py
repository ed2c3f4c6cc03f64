"""DVC stage report: paper_comparison.md, figures, headline metrics, MLflow runs."""

import _interpreter  # noqa: F401  (the venv's python: stages/_interpreter.py)
from vnrrt.evaluation.paper_comparison.stage import run_report
from vnrrt.stage_cli import stage_main

if __name__ == "__main__":
    stage_main("report", run_report, __doc__)
