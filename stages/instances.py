"""DVC stage instances: the evaluation instances with their A* and exact optima."""

import _interpreter  # noqa: F401  (the venv's python: stages/_interpreter.py)
from vnrrt.cli.stage import stage_main
from vnrrt.pipeline.evaluation import run_instances

if __name__ == "__main__":
    stage_main("instances", run_instances, __doc__)
