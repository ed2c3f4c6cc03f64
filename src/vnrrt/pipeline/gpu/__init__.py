"""The paper's network on a GPU machine, in one short lease (issue 27).

* :mod:`.bundle` (here, with Hydra): compose ``conf/`` into the run's settings and copy the
  instances file into one folder that travels to the machine (``data/gpu/bundle``).
* :mod:`.run` (there; ``scripts/gpu/paper_network.sh``): shards, both trainings, throughput,
  heatmaps of the instances and metrics, within a time budget, written to an output folder
  that fits the machine's return limits. It needs only what that machine has (torch,
  Lightning, numba, OpenCV, numpy): no Hydra, OmegaConf, MLflow or DVC.
* :mod:`vnrrt.data.returned` (here): the return limits and
  :func:`~vnrrt.data.returned.read_returned`, the one reader of the returned files (schema
  checks), for the pipeline's heatmap source.
"""
