"""DVC stage evaluate (see vnrrt.evaluation.stage.run_evaluate)."""

import argparse
import logging

from vnrrt.config import load_params
from vnrrt.evaluation.stage import run_evaluate

if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--params", default="params.yaml")
    args = parser.parse_args()
    logging.basicConfig(level=logging.INFO, format="%(levelname)s %(name)s: %(message)s")
    run_evaluate(load_params(args.params))
