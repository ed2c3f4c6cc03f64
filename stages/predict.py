"""DVC stage predict: heatmaps of both networks for the evaluation instances (vnrrt.pipeline)."""

import argparse
import logging

from vnrrt.config import load_params
from vnrrt.pipeline import run_predict

if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--params", default="params.yaml")
    args = parser.parse_args()
    logging.basicConfig(level=logging.INFO, format="%(levelname)s %(name)s: %(message)s")
    run_predict(load_params(args.params))
