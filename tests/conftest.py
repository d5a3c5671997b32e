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
    """The tests marked ``slow`` first, each in its collection order: pytest-xdist deals
    the first quarter of the items round-robin to its workers, so the long tests start at
    once on every core instead of leaving one of them running alone at the end (the
    whole suite's time on two cores is then close to half its summed time)."""
    items.sort(key=lambda item: item.get_closest_marker("slow") is None)
