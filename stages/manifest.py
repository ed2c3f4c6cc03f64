"""DVC stage manifest: shard checksums and counts, and the dataset metrics."""

import _interpreter  # noqa: F401  (the venv's python: stages/_interpreter.py)
from vnrrt.cli.stage import stage_main
from vnrrt.pipeline.data import run_manifest

if __name__ == "__main__":
    stage_main("manifest", run_manifest, __doc__)
