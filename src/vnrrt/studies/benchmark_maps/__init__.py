"""The benchmark-maps study (issue 52; ``reports/benchmark_maps.md``): the planners, the
trained networks and the oracle envelopes on MovingAI benchmark maps, out of the networks'
training distribution. :mod:`.design` (settings, query sampling, instances, configurations),
:mod:`.summary` (statistics), :mod:`.report`, :mod:`.runs` (its MLflow run)."""
