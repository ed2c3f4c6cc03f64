"""DVC stage ideas: the oracle study and regime sweep merged, sampling_ideas.md, figures."""

import _interpreter  # noqa: F401  (the venv's python: stages/_interpreter.py)
from vnrrt.evaluation.sampling_ideas.stage import run_ideas
from vnrrt.stage_cli import stage_main

if __name__ == "__main__":
    stage_main("ideas", run_ideas, __doc__)
