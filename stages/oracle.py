"""DVC stage oracle@<k>: part k of the oracle study (oracle heatmaps, quality curve)."""

from vnrrt.cli.stage import stage_main
from vnrrt.pipeline.sampling_ideas import run_oracle_part

if __name__ == "__main__":
    stage_main("oracle", run_oracle_part, __doc__, "part", int, "part id (oracle.parts)")
