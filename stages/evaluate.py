"""DVC stage evaluate: the trial parts merged, statistics and convergence curves."""

import _interpreter  # noqa: F401  (the venv's python: stages/_interpreter.py)
from vnrrt.cli.stage import stage_main
from vnrrt.pipeline.paper_comparison import run_evaluate

if __name__ == "__main__":
    stage_main("evaluate", run_evaluate, __doc__)
