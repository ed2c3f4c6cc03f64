"""DVC stage instances: the evaluation instances with their A* and exact optima."""

from vnrrt.cli.stage import stage_main
from vnrrt.pipeline.evaluation import run_instances

if __name__ == "__main__":
    stage_main("instances", run_instances, __doc__)
