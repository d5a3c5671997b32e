"""A pool worker runs OpenBLAS on one thread (issue 25, point 7): a worker per core with a
BLAS thread per core each made the small dense solves of harmonic balance wait on each
other (13x the CPU time per 125-unknown solve on 2 cores)."""

import ctypes
import os

import numpy as np
import pytest
from gearsym.solver.executor import map_tasks

_GETTERS = (
    "openblas_get_num_threads",
    "openblas_get_num_threads64_",
    "scipy_openblas_get_num_threads",
    "scipy_openblas_get_num_threads64_",
)


def _blas_threads(_=None) -> list:
    """The thread count of every OpenBLAS loaded in this process."""
    np.linalg.solve(np.eye(3), np.ones(3))  # NumPy's BLAS is loaded and started
    with open("/proc/self/maps", encoding="utf-8") as fh:
        paths = sorted({line.split()[-1] for line in fh if "openblas" in line.lower()})
    counts = []
    for path in paths:
        lib = ctypes.CDLL(path)
        counts += [getattr(lib, n)() for n in _GETTERS if hasattr(lib, n)]
    return counts


def _set_blas_threads(n: int) -> None:
    """Every OpenBLAS loaded in this process on ``n`` threads."""
    with open("/proc/self/maps", encoding="utf-8") as fh:
        paths = sorted({line.split()[-1] for line in fh if "openblas" in line.lower()})
    for path in paths:
        lib = ctypes.CDLL(path)
        for name in _GETTERS:
            setter = getattr(lib, name.replace("_get_", "_set_"), None)
            if setter is not None:
                setter(n)


@pytest.mark.skipif(not os.path.exists("/proc/self/maps"), reason="reads /proc/self/maps")
def test_pool_workers_run_blas_on_one_thread():
    here = _blas_threads()
    if not here:
        pytest.skip("NumPy is not linked to OpenBLAS here")
    # a pytest-xdist worker runs one thread already (tests/conftest.py): two for the test
    _set_blas_threads(2)
    try:
        if max(_blas_threads()) < 2:
            pytest.skip("OpenBLAS runs one thread in this process: nothing to show")
        got = map_tasks(_blas_threads, [0, 1], executor="processes", workers=2)
    finally:
        _set_blas_threads(max(here))
    assert got == [[1] * len(here)] * 2
