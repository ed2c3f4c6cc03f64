"""DVC stage report: paper_comparison.md, figures, headline metrics, MLflow runs."""

import _interpreter  # noqa: F401  (the venv's python: stages/_interpreter.py)
from vnrrt.cli.stage import stage_main
from vnrrt.pipeline.paper_comparison import run_report

if __name__ == "__main__":
    stage_main("report", run_report, __doc__)
