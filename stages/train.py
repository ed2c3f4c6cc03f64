"""DVC stage train@<network>: train VertexNet or the NRRT* network."""

import _interpreter  # noqa: F401  (the venv's python: stages/_interpreter.py)
from vnrrt.cli.stage import stage_main
from vnrrt.pipeline.training import run_train

if __name__ == "__main__":
    stage_main("train", run_train, __doc__, "network", str, "vertexnet or nrrtnet")
