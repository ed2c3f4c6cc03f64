"""DVC stage train_<network>: train VertexNet or the NRRT* network (vnrrt.pipeline.run_train)."""

from vnrrt.pipeline import run_train
from vnrrt.stage_cli import stage_main

if __name__ == "__main__":
    stage_main(run_train, __doc__, "network", str, "vertexnet or nrrtnet (networks.*)")
