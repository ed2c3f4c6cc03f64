"""DVC stage oracle@<k>: part k of the oracle study (oracle heatmaps, quality curve)."""

import _interpreter  # noqa: F401  (the venv's python: stages/_interpreter.py)
from vnrrt.cli.stage import stage_main
from vnrrt.pipeline.sampling_ideas import run_oracle_part

if __name__ == "__main__":
    stage_main("oracle", run_oracle_part, __doc__, "part", int, "part id (oracle.parts)")
