"""DVC stage ideas: the oracle study and regime sweep merged, sampling_ideas.md, figures."""

import _interpreter  # noqa: F401  (the venv's python: stages/_interpreter.py)
from vnrrt.cli.stage import stage_main
from vnrrt.pipeline.sampling_ideas import run_ideas

if __name__ == "__main__":
    stage_main("ideas", run_ideas, __doc__)
