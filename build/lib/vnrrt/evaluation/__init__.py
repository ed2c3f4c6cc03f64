"""Evaluation of the planners: trial statistics and the report against the paper."""
