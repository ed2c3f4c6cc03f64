"""DVC stage report (see vnrrt.evaluation.stage.run_report)."""

import argparse
import logging

from vnrrt.config import load_params
from vnrrt.evaluation.stage import run_report

if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--params", default="params.yaml")
    args = parser.parse_args()
    logging.basicConfig(level=logging.INFO, format="%(levelname)s %(name)s: %(message)s")
    run_report(load_params(args.params))
