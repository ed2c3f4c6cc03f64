"""DVC stage shard@<id>: generate and label one shard of maps."""

from vnrrt.cli.stage import stage_main
from vnrrt.pipeline.data import run_shard

if __name__ == "__main__":
    stage_main("shard", run_shard, __doc__, "shard", int, "shard id (scale.shards)")
