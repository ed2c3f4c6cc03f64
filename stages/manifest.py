"""DVC stage manifest: shard checksums and counts, and the dataset metrics."""

import _interpreter  # noqa: F401  (the venv's python: stages/_interpreter.py)
from vnrrt.data.stage import run_manifest
from vnrrt.stage_cli import stage_main

if __name__ == "__main__":
    stage_main("manifest", run_manifest, __doc__)
