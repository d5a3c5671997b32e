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
