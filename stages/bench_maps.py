"""DVC stage bench_maps@benchmark_maps: the planners and networks on MovingAI maps, the report."""

import _interpreter  # noqa: F401  (the venv's python: stages/_interpreter.py)
from vnrrt.cli.stage import stage_main
from vnrrt.pipeline.benchmark_maps import run_bench_maps

if __name__ == "__main__":
    stage_main("bench_maps", run_bench_maps, __doc__, "name", str, "bench_maps.report entry")
