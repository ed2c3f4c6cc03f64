"""DVC stage manifest: shard checksums and counts, and the dataset metrics."""

from vnrrt.pipeline import run_manifest
from vnrrt.stage_cli import stage_main

if __name__ == "__main__":
    stage_main(run_manifest, __doc__)
