"""Heatmaps from trained networks: one call for one instance (:func:`heatmap`), and the
pipeline's batch prediction of the evaluation instances (:mod:`.batch`,
:mod:`vnrrt.pipeline.predict`)."""

from vnrrt.predict.api import heatmap, load_model

__all__ = ["heatmap", "load_model"]
