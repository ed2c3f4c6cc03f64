"""DVC stage predict_named: heatmaps of the named maps, prediction metrics, Fig. 3."""

from vnrrt.pipeline import run_predict_named
from vnrrt.stage_cli import stage_main

if __name__ == "__main__":
    stage_main(run_predict_named, __doc__)
