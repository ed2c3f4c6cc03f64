"""DVC stage shard@<id>: generate and label one shard of maps."""

import _interpreter  # noqa: F401  (the venv's python: stages/_interpreter.py)
from vnrrt.cli.stage import stage_main
from vnrrt.pipeline.data import run_shard

if __name__ == "__main__":
    stage_main("shard", run_shard, __doc__, "shard", int, "shard id (scale.shards)")
