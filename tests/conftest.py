import os

import pytest
from gearsym.derive import derive_model, load_target
from gearsym.derive.build import project_root


@pytest.fixture(scope="session")
def root():
    return project_root()


@pytest.fixture(scope="session")
def light_model(root):
    return derive_model(load_target(root / "scenes" / "reference-light.toml"))


@pytest.fixture(scope="session")
def diso_model(root):
    return derive_model(load_target(root / "scenes" / "topologies" / "diso.toml"))


def pytest_collection_modifyitems(items):
    """The tests marked ``slow`` first, each in its collection order.  pytest-xdist
    (``--dist load``) sends each worker a block of consecutive items at the start and then
    refills whichever worker frees up from the items left, so the long tests all start
    early, the short ones fill in round them, and no long test is left running alone at
    the end (measured: the suite's time on two cores 961 -> 805 s with the trims of the
    same change; ``--dist loadscope`` 925 s).  The order is the same on every worker, as
    xdist requires."""
    items.sort(key=lambda item: item.get_closest_marker("slow") is None)


def pytest_configure(config):
    """Under pytest-xdist (the README's ``-n auto``) each worker is one of a worker per
    core, so its OpenBLAS runs one thread, as the toolkit's own pool workers do
    (``solver/executor.py``, issue 25 point 7): with a BLAS thread per core in each worker
    the small dense solves thrash (measured: a harmonic-balance continuation of the dead
    zone took 24 s beside another instead of 2.7 s)."""
    if os.environ.get("PYTEST_XDIST_WORKER"):
        from gearsym.solver.executor import _one_blas_thread

        _one_blas_thread()
