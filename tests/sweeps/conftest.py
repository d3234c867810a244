"""The environment is restored after each sweep test module: Dask's nannies write their worker
settings (OMP_NUM_THREADS=1, MALLOC_TRIM_THRESHOLD_=65536, ...) into the environment of the
process that starts them, and later tests' subprocesses would inherit them."""

from __future__ import annotations

import os

import pytest


@pytest.fixture(scope="module", autouse=True)
def restored_environment():
    saved = dict(os.environ)
    yield
    os.environ.clear()
    os.environ.update(saved)
