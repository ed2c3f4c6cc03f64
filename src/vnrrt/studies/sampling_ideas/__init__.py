"""The sampling-ideas study (``sampling_ideas.md``): what each sampling idea gives with
perfect (oracle) heatmaps, the heatmap-quality curve and the planner regime (stages
``oracle@<k>``, ``regime@<k>`` and ``ideas``)."""
