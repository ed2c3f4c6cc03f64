"""DVC stage oracle@<k>: part k of the oracle study (oracle heatmaps, quality curve)."""

import _interpreter  # noqa: F401  (the venv's python: stages/_interpreter.py)
from vnrrt.evaluation.sampling_ideas.stage import run_oracle_part
from vnrrt.stage_cli import stage_main

if __name__ == "__main__":
    stage_main("oracle", run_oracle_part, __doc__, "part", int, "part id (oracle.parts)")
