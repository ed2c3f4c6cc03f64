"""Sharded datasets: the shard format, building shards, reading them, the manifest."""
