"""DVC stage predict@<k>: heatmaps of the networks for part k of the instances."""

import _interpreter  # noqa: F401  (the venv's python: stages/_interpreter.py)
from vnrrt.cli.stage import stage_main
from vnrrt.pipeline.predict import run_predict_part

if __name__ == "__main__":
    stage_main("predict", run_predict_part, __doc__, "part", int, "part id (predict.parts)")
