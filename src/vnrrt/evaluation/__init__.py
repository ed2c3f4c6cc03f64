"""Evaluation of the planners: a shared engine and the two studies built on it.

The engine (what runs and how it is measured):

* :mod:`.config`: the ``eval``, ``stats``, ``oracle`` and ``regime`` sections, typed;
* :mod:`.keys`: :class:`~.keys.ConfigKey`, the one configuration key (planner, tau, heatmap
  source, informed) with one way to write and read it;
* :mod:`.protocol`: configurations, stop rules, trial counts, paired seeds, jobs and parts;
* :mod:`.sources`: heatmap sources (trained networks' heatmaps, oracle heatmaps);
* :mod:`.trials`: runs jobs into rows; :mod:`.table`: the trial table; :mod:`.stats`:
  paired, clustered statistics and verdicts; :mod:`.paper_tables`: the paper's numbers;
* :mod:`.instances`: builds the instances file (format: :mod:`vnrrt.data.instances`);
* :mod:`.stage`: the stages ``instances`` and ``trials@<k>``.

The studies, one subpackage each, named after their report:

* :mod:`.paper_comparison` (``paper_comparison.md``): ``summary`` (stage ``evaluate``),
  ``report``, ``runs`` (MLflow) and ``stage`` (``evaluate``, ``report``);
* :mod:`.sampling_ideas` (``sampling_ideas.md``): ``design`` (oracle study, regime sweep),
  ``summary``, ``report``, ``runs`` and ``stage`` (``oracle@<k>``, ``regime@<k>``,
  ``ideas``).
"""
