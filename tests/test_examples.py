"""The scripts of docs/examples/ run as a user runs them and write what they promise.

Each runs in a fresh interpreter with an output folder and its own cache root
(``GEARSYM_CACHE``), so that nothing is written into the user's home and the compiled
libraries and derived models are built from scratch, as on a first run.
"""

import csv
import os
import runpy
import subprocess
import sys
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np
import pytest
import scipy.io
from matplotlib.figure import Figure

EXAMPLES = Path(__file__).resolve().parents[1] / "docs" / "examples"


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


def _written(out, *names):
    for name in names:
        assert (out / name).is_file() and (out / name).stat().st_size > 0, name


def test_every_example_is_tested_here():
    assert sorted(p.name for p in EXAMPLES.glob("*.py")) == [
        "notebook.py",
        "orbit_and_continuation.py",
        "own_scene.py",
        "planetary.py",
        "sweep_with_figure.py",
    ]


@pytest.mark.slow
def test_planetary(tmp_path):
    # the marine stage's fixed-carrier modes: 1 rigid-body, 6 translational pairs, 5
    # rotational (Lin and Parker's structure for 3 planets: no planet modes)
    out, stdout = _run("planetary.py", tmp_path)
    assert "mode types: 1 rigid-body, 12 translational, 5 rotational" in stdout
    # no mesh frequency in a planetary set's file: its summary says so, with no NaN
    assert "(no mesh frequency stated)" in stdout and "nan" not in stdout.lower()
    assert "907.4088 Hz, translational, x2" in stdout
    assert "the mesh frequency first meets mode 1 (translational)" in stdout
    _written(out, "campbell.png", "carrier_sweep.json", "parametric.png", "mesh_response.png")
    sweep = __import__("json").loads((out / "carrier_sweep.json").read_text(encoding="utf-8"))
    assert len(sweep["speeds_rpm"]) == 31 and sweep["mesh"]["ring_teeth"] == 100
    # the nonlinear model: the ring meshes' teeth part near 6986 / 2 Hz, the sun meshes' not
    # (tests/derive/test_planetary_dynamics.py checks the band against the hand assembly)
    apart = __import__("re").search(r"teeth apart at 3500 Hz: (\{.*\})", stdout).group(1)
    apart = __import__("ast").literal_eval(apart)
    assert apart["rp1"] > 0 and apart["sp1"] == 0
    resp = __import__("json").loads((out / "mesh_response.json").read_text(encoding="utf-8"))
    assert resp["band_hz_by_kind"]["ring-planet"] and not resp["band_hz_by_kind"]["sun-planet"]


def test_orbit_and_continuation(tmp_path):
    out, stdout = _run("orbit_and_continuation.py", tmp_path)
    assert "stable: True" in stdout and "Liouville" in stdout
    _written(out, "branch.csv", "branch.mat")
    with open(out / "branch.csv", newline="") as fh:  # the header block: "# key: value"
        rows = list(csv.reader(line for line in fh if not line.startswith("#")))
    assert rows[0][:3] == ["lambda", "stable", "max_multiplier"] and len(rows) > 2
    lam = [float(r[0]) for r in rows[1:]]
    assert lam[0] == 0.8 and lam[-1] == 1.0
    table = scipy.io.loadmat(out / "branch.mat", simplify_cells=True)["table"]
    np.testing.assert_array_equal(table["lambda"], lam)


def test_sweep_with_figure(tmp_path):
    out, stdout = _run("sweep_with_figure.py", tmp_path)
    assert stdout.count("lambda = ") == 6
    _written(out, "bifurcation.png", "sweep.json", "sweep.csv")
    with open(out / "sweep.csv", newline="") as fh:  # the header block: "# key: value"
        rows = list(csv.reader(line for line in fh if not line.startswith("#")))
    assert rows[0][:2] == ["lambda", "status"] and len(rows) == 7


def test_own_scene_derives_into_the_given_cache(tmp_path):
    out, stdout = _run("own_scene.py", tmp_path)
    models = tmp_path / "cache" / "models"
    assert str(models) in stdout
    assert list(models.glob("my_light_*.py"))
    _written(out, "my-light.toml", "point.mat")
    mat = scipy.io.loadmat(out / "point.mat", simplify_cells=True)
    assert set(mat["table"]) == {"tau", "u", "v", "du", "dv"}


@pytest.mark.slow
def test_notebook_builds_figures_from_the_api_alone(tmp_path, monkeypatch):
    """The notebook-style script (issue 25, point 6): its cells import nothing but
    ``gearsym`` (and the standard library), each result draws through ``gearsym.plot``
    into a Figure, and nothing is written unless an output folder is given."""
    script = EXAMPLES / "notebook.py"
    imports = [
        line.split()[1]
        for line in script.read_text(encoding="utf-8").splitlines()
        if line.startswith(("import ", "from "))
    ]
    assert set(imports) == {"gearsym", "sys", "pathlib"}, imports
    monkeypatch.chdir(tmp_path)
    monkeypatch.setattr(sys, "argv", [str(script)])
    names = runpy.run_path(str(script), run_name="notebook")  # as a notebook runs it
    figures = names["figures"]
    try:
        assert list(figures) == [
            "point",
            "bifurcation",
            "map-motion",
            "map-extremes",
            "multipliers",
            "branch",
            "frequency-response",
            "campbell",
            "bifurcation-physical",
        ]
        assert all(isinstance(f, Figure) and f.axes for f in figures.values())
        assert not list(tmp_path.iterdir())  # saving is the caller's choice
    finally:
        plt.close("all")
    # run as a script with a folder: every figure saved there
    out, stdout = _run("notebook.py", tmp_path)
    assert stdout.count("wrote ") == len(figures)
    _written(out, *(f"{name}.png" for name in figures))
