"""DVC stage shard@<id>: generate and label one shard of maps."""

import _interpreter  # noqa: F401  (the venv's python: stages/_interpreter.py)
from vnrrt.data.stage import run_shard
from vnrrt.stage_cli import stage_main

if __name__ == "__main__":
    stage_main("shard", run_shard, __doc__, "shard", int, "shard id (scale.shards)")
