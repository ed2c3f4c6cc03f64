"""DVC stage evaluate: the trial parts merged, statistics and convergence curves."""

from vnrrt.cli.stage import stage_main
from vnrrt.pipeline.paper_comparison import run_evaluate

if __name__ == "__main__":
    stage_main("evaluate", run_evaluate, __doc__)
