"""DVC stage evaluate: merged trials, summary metrics and convergence curves."""

from vnrrt.evaluation.stage import run_evaluate
from vnrrt.stage_cli import stage_main

if __name__ == "__main__":
    stage_main(run_evaluate, __doc__)
