"""DVC stage evaluate: the trial parts merged, statistics and convergence curves."""

import _interpreter  # noqa: F401  (the venv's python: stages/_interpreter.py)
from vnrrt.evaluation.paper_comparison.stage import run_evaluate
from vnrrt.stage_cli import stage_main

if __name__ == "__main__":
    stage_main("evaluate", run_evaluate, __doc__)
