"""The scripts of docs/examples/ run as a user runs them and write what they promise."""

import csv
import os
import subprocess
import sys

import numpy as np
import pytest
import scipy.io
from gearsym.derive.build import project_root

EXAMPLES = project_root() / "docs" / "examples"


def _run(name, tmp_path):
    env = dict(os.environ, GEARSYM_CACHE=str(tmp_path / "cache"))
    out = tmp_path / "out"
    out.mkdir()
    done = subprocess.run(
        [sys.executable, str(EXAMPLES / name), str(out)],
        capture_output=True,
        text=True,
        env=env,
        cwd=tmp_path,
        timeout=300,
    )
    assert done.returncode == 0, done.stderr[-2000:]
    return out, done.stdout


def test_every_example_is_listed_here():
    assert sorted(p.name for p in EXAMPLES.glob("*.py")) == [
        "orbit_and_continuation.py",
        "own_scene.py",
        "sweep_with_figure.py",
    ]


def test_orbit_and_continuation(tmp_path):
    out, stdout = _run("orbit_and_continuation.py", tmp_path)
    assert "stable: True" in stdout
    with open(out / "branch.csv", newline="") as fh:
        rows = list(csv.reader(fh))
    assert rows[0][:3] == ["lambda", "stable", "max_multiplier"] and len(rows) > 2
    table = scipy.io.loadmat(out / "branch.mat", simplify_cells=True)["table"]
    np.testing.assert_allclose(table["lambda"], [float(r[0]) for r in rows[1:]], rtol=1e-15)


def test_sweep_with_figure(tmp_path):
    out, stdout = _run("sweep_with_figure.py", tmp_path)
    assert stdout.count("lambda = ") == 6
    for name in ("bifurcation.png", "sweep.json", "sweep.csv"):
        assert (out / name).stat().st_size > 0, name


@pytest.mark.slow
def test_own_scene_derives_into_the_given_cache(tmp_path):
    out, stdout = _run("own_scene.py", tmp_path)
    assert str(tmp_path / "cache" / "models") in stdout
    assert list((tmp_path / "cache" / "models").glob("my_light_*.py"))
    mat = scipy.io.loadmat(out / "point.mat", simplify_cells=True)
    assert set(mat["table"]) == {"tau", "u", "v", "du", "dv"}
