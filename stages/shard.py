"""DVC stage shard@<id>: generate and label one shard of maps (see vnrrt.pipeline)."""

import argparse
import logging

from vnrrt.config import load_params
from vnrrt.pipeline import run_shard

if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--shard", type=int, required=True, help="shard id (scale.shards)")
    parser.add_argument("--params", default="params.yaml")
    args = parser.parse_args()
    logging.basicConfig(level=logging.INFO, format="%(levelname)s %(name)s: %(message)s")
    run_shard(load_params(args.params), args.shard)
