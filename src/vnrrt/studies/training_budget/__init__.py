"""The networks over a training budget (``training_budget.md``; issue 24): both networks
trained at each budget of ``budget.steps``, their heatmap metrics in multiples of a uniform
map, the paired speed-ups over RRT* of NRRT*, VNRRT* and M-VNRRT* (``planner.tau``), the
VNRRT*/NRRT* ratio, and their trends over the images seen (stages ``budget_trials@<steps>``
and ``budget_report@training_budget``; the trainings and heatmaps: ``budget_train``,
``budget_predict``)."""
