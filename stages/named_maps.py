"""DVC stage named_maps: the five named maps (Fig. 4) as a shard and a figure."""

import _interpreter  # noqa: F401  (the venv's python: stages/_interpreter.py)
from vnrrt.cli.stage import stage_main
from vnrrt.pipeline.data import run_named_maps

if __name__ == "__main__":
    stage_main("named_maps", run_named_maps, __doc__)
