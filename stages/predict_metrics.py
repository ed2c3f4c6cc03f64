"""DVC stage predict_metrics: heatmap metrics, inference time and Fig. 3."""

import _interpreter  # noqa: F401  (the venv's python: stages/_interpreter.py)
from vnrrt.cli.stage import stage_main
from vnrrt.pipeline.predict import run_predict_metrics

if __name__ == "__main__":
    stage_main("predict_metrics", run_predict_metrics, __doc__)
