"""Shared test fixtures: hypothesis profile, small random grids, repository paths."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, settings

REPO = Path(__file__).resolve().parents[1]

settings.register_profile(
    "default", deadline=None, max_examples=60, suppress_health_check=[HealthCheck.too_slow]
)
settings.register_profile("ci", parent=settings.get_profile("default"), derandomize=True)
settings.load_profile("ci" if os.environ.get("CI") else "default")


@pytest.fixture(scope="session")
def repo() -> Path:
    return REPO


def random_grid(seed: int, h: int = 24, w: int = 24, density: float = 0.3) -> np.ndarray:
    """A small random occupancy grid (uint8, 1 = obstacle) for property tests."""
    rng = np.random.default_rng(seed)
    return (rng.random((h, w)) < density).astype(np.uint8)
