"""DVC stage oracle@<k>: part k of the oracle study (oracle heatmaps, quality curve)."""

from vnrrt.evaluation.sampling_ideas.stage import run_oracle_part
from vnrrt.stage_cli import stage_main

if __name__ == "__main__":
    stage_main("oracle", run_oracle_part, __doc__, "part", int, "part id (oracle.parts)")
