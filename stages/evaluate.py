"""DVC stage evaluate: the trial parts merged, statistics and convergence curves."""

from vnrrt.evaluation.paper_comparison.stage import run_evaluate
from vnrrt.stage_cli import stage_main

if __name__ == "__main__":
    stage_main("evaluate", run_evaluate, __doc__)
