"""Shared fixtures of the MPM tests."""

from __future__ import annotations

import numba
import pytest


@pytest.fixture(scope="module")
def two_threads():
    """Run a module's simulations on (at most) 2 numba threads, as the benchmarks do."""
    old = numba.get_num_threads()
    numba.set_num_threads(min(2, numba.config.NUMBA_NUM_THREADS))
    yield
    numba.set_num_threads(old)
