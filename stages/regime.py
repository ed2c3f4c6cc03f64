"""DVC stage regime@<k>: part k of the planner-regime sweep."""

import _interpreter  # noqa: F401  (the venv's python: stages/_interpreter.py)
from vnrrt.cli.stage import stage_main
from vnrrt.pipeline.sampling_ideas import run_regime_part

if __name__ == "__main__":
    stage_main("regime", run_regime_part, __doc__, "part", int, "part id (regime.parts)")
