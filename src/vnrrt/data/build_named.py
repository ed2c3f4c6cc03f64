"""The five named maps (:mod:`vnrrt.maps.named`) labelled and written as a shard."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from vnrrt.config import asdict
from vnrrt.data.build import write_labelled
from vnrrt.data.config import LabelsConfig
from vnrrt.data.label import label_map
from vnrrt.data.reader import TEST
from vnrrt.maps.named import NAMES, named_map


def build_named_maps(out: str | Path, size: int, labels: LabelsConfig) -> dict:
    """Write the five named maps (:mod:`vnrrt.maps.named`) as a shard of 5 test instances."""
    maps = [named_map(name, size) for name in NAMES]
    results = [
        (fm, label_map(fm, labels.vertex_steps, labels.tie_break, labels.tie_tolerance))
        for fm in maps
    ]
    split = np.full(len(maps), TEST, np.uint8)
    meta = {"names": list(NAMES), "map_size": size, "labels": asdict(labels)}
    return write_labelled(out, results, np.arange(len(maps)), split, **meta)
