"""DVC stage instances: the evaluation instances with their A* and exact optima."""

import _interpreter  # noqa: F401  (the venv's python: stages/_interpreter.py)
from vnrrt.evaluation.stage import run_instances
from vnrrt.stage_cli import stage_main

if __name__ == "__main__":
    stage_main("instances", run_instances, __doc__)
