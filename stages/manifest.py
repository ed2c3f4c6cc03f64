"""DVC stage manifest: shard checksums and counts, and the dataset metrics."""

from vnrrt.data.stage import run_manifest
from vnrrt.stage_cli import stage_main

if __name__ == "__main__":
    stage_main("manifest", run_manifest, __doc__)
