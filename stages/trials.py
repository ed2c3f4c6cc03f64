"""DVC stage trials@<k>: part k of the evaluation protocol's planner trials."""

import _interpreter  # noqa: F401  (the venv's python: stages/_interpreter.py)
from vnrrt.cli.stage import stage_main
from vnrrt.pipeline.evaluation import run_trials_part

if __name__ == "__main__":
    stage_main("trials", run_trials_part, __doc__, "part", int, "part id (eval.parts)")
