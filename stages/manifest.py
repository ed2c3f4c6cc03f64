"""DVC stage manifest: shard checksums and counts, and the dataset metrics."""

from vnrrt.cli.stage import stage_main
from vnrrt.pipeline.data import run_manifest

if __name__ == "__main__":
    stage_main("manifest", run_manifest, __doc__)
