"""DVC stage named_maps: the five named maps (Fig. 4) as a shard and a figure."""

import argparse
import logging

from vnrrt.config import load_params
from vnrrt.pipeline import run_named_maps

if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--params", default="params.yaml")
    args = parser.parse_args()
    logging.basicConfig(level=logging.INFO, format="%(levelname)s %(name)s: %(message)s")
    run_named_maps(load_params(args.params))
