"""Shared fixtures: the paper's manipulator and a seeded RNG."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from intervalkin.geometry import default_geometry

DATA = Path(__file__).parent / "data"


@pytest.fixture(scope="session")
def paper_geometry():
    return default_geometry()


@pytest.fixture
def rng():
    return np.random.default_rng(20261121)
