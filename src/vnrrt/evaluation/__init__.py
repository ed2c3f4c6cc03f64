"""The evaluation engine, study-free (the studies: :mod:`vnrrt.studies`):

* :mod:`.config`: the ``eval``, ``stats``, ``oracle`` and ``regime`` sections, typed;
* :mod:`.keys`: :class:`~.keys.ConfigKey`, the one configuration key (planner, tau, heatmap
  source, informed) with one way to write and read it;
* :mod:`.protocol`: configurations, stop rules, trial counts, paired seeds, jobs and parts;
* :mod:`.sources`: heatmap sources (trained networks' heatmaps, oracle heatmaps);
  :mod:`.oracles`: the oracle heatmaps; :mod:`.sampling`: the planners' samplers by key;
* :mod:`.trials`: runs jobs into rows; :mod:`.table`: the trial table; :mod:`.stats`:
  paired, clustered statistics and verdicts;
* :mod:`.instances`: builds the instances file (format: :mod:`vnrrt.data.instances`).

The stages that run it: :mod:`vnrrt.pipeline.evaluation` (``instances``, ``trials@<k>``).
"""
