"""DVC stage regime@<k>: part k of the planner-regime sweep."""

import _interpreter  # noqa: F401  (the venv's python: stages/_interpreter.py)
from vnrrt.evaluation.sampling_ideas.stage import run_regime_part
from vnrrt.stage_cli import stage_main

if __name__ == "__main__":
    stage_main("regime", run_regime_part, __doc__, "part", int, "part id (regime.parts)")
