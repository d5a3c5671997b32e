from pathlib import Path

import pytest
from gearsym.derive.build import build_files, project_root, write_files
from gearsym.solver.system import System

HERE = Path(__file__).parent


@pytest.fixture(scope="session")
def duffing():
    return System.load(HERE / "duffing_model.py")


@pytest.fixture(scope="session")
def linear_system(tmp_path_factory):
    """The reference topology's linear limit with harmonic forcing: constant stiffness,
    g(u) = u, transmission error on (so the steady state has a closed form)."""
    tmp = tmp_path_factory.mktemp("linear")
    text = (project_root() / "scenes" / "reference-light.toml").read_text()
    head, _, rest = text.partition("[features]")
    rest = rest[rest.index("[parameters]") :]
    topo = (project_root() / "scenes" / "topologies" / "diso.toml").as_posix()
    head = head.replace('topology = "topologies/diso.toml"', f'topology = "{topo}"')
    head = head.replace('name = "reference-light"', 'name = "linear-forced"')
    features = (
        '[features]\nstiffness_harmonics = 0\nbacklash = "linear"\n'
        "transmission_error = true\nmesh_phase = true\ndamping_coupling = true\n\n"
    )
    scene = tmp / "linear.toml"
    scene.write_text(head + features + rest)
    write_files(build_files([scene]).files, tmp)
    return System.load(tmp / "generated" / "linear_forced.py")
