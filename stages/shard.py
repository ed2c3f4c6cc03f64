"""DVC stage shard@<id>: generate and label one shard of maps (vnrrt.pipeline.run_shard)."""

from vnrrt.pipeline import run_shard
from vnrrt.stage_cli import stage_main

if __name__ == "__main__":
    stage_main(run_shard, __doc__, "shard", int, "shard id (scale.shards)")
