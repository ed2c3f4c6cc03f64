"""DVC stage train_<network>: train VertexNet or the NRRT* network (see vnrrt.pipeline)."""

import argparse
import logging

from vnrrt.config import load_params
from vnrrt.pipeline import run_train

if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--network", required=True, help="vertexnet or nrrtnet (networks.*)")
    parser.add_argument("--params", default="params.yaml")
    args = parser.parse_args()
    logging.basicConfig(level=logging.INFO, format="%(levelname)s %(name)s: %(message)s")
    run_train(load_params(args.params), args.network)
