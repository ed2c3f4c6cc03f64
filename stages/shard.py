"""DVC stage shard@<id>: generate and label one shard of maps."""

from vnrrt.data.stage import run_shard
from vnrrt.stage_cli import stage_main

if __name__ == "__main__":
    stage_main("shard", run_shard, __doc__, "shard", int, "shard id (scale.shards)")
