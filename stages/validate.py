"""DVC stage validate: check the whole composed configuration before any work."""

import _interpreter  # noqa: F401  (the venv's python: stages/_interpreter.py)
from vnrrt.cli.stage import stage_main
from vnrrt.pipeline.validate import run_validate

if __name__ == "__main__":
    stage_main("validate", run_validate, __doc__)
