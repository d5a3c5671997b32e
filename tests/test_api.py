"""`import gearsym` is the public API (docs/api.md): a small surface that resolves, loads
scenes by any spelling, fails clearly on a wrong name, and exports results."""

import csv
import types

import gearsym
import numpy as np
import pytest


@pytest.fixture(autouse=True)
def _own_cache(tmp_path, monkeypatch):
    """Nothing goes into the user's cache: the shipped models load from generated/, and
    the runs below use CVODES, which compiles nothing."""
    monkeypatch.setenv("GEARSYM_CACHE", str(tmp_path / "cache"))


def test_the_public_names_are_exactly_all_and_resolve():
    assert len(gearsym.__all__) == len(set(gearsym.__all__)) < 40
    for name in gearsym.__all__:
        assert getattr(gearsym, name) is not None, name
    # Besides __all__, only the package's own sub-packages (derive, solver, resolve, ...).
    public = {n for n in dir(gearsym) if not n.startswith("_")}
    extra = public - set(gearsym.__all__)
    assert all(isinstance(getattr(gearsym, n), types.ModuleType) for n in extra), extra
    assert all(getattr(gearsym, n).__name__ == f"gearsym.{n}" for n in extra), extra
    star = {}
    exec("from gearsym import *", star)
    assert set(star) - {"__builtins__"} == set(gearsym.__all__)


def test_load_accepts_hyphens_underscores_and_overrides():
    a = gearsym.load("reference-light")
    b = gearsym.load("reference_light", **{"lambda": 0.8})
    assert a.model_hash == b.model_hash and len(a.model_hash) == 64
    assert b.values == {"lambda": 0.8} and not np.array_equal(a.p, b.p)
    assert b.with_values(**{"lambda": 0.1}).model_hash == a.model_hash


def test_a_missing_name_fails_listing_the_built_in_ones():
    with pytest.raises(
        gearsym.InputError, match="built-in: diso-bearings-light, reference-dead-zone"
    ) as err:
        gearsym.load("no-such-scene")
    assert "neither a file nor a built-in scene or topology" in str(err.value)
    with pytest.raises(gearsym.InputError, match="did you mean 'reference-light'"):
        gearsym.load("reference-lihgt")
    with pytest.raises(gearsym.InputError, match="file not found"):
        gearsym.load("no/such/scene.toml")


def test_an_unknown_parameter_is_named():
    with pytest.raises(KeyError, match="lamda.*scene parameters"):
        gearsym.load("reference-light", lamda=0.8)


def test_a_trajectory_exports_to_csv_json_and_mat(tmp_path):
    system = gearsym.load("reference-light", **{"lambda": 0.8})
    run = gearsym.simulate(system, method="cvodes", transient=10, periods=2, samples_per_period=8)
    path = run.save(tmp_path / "run.csv")
    with open(path, newline="") as fh:
        rows = list(csv.reader(line for line in fh if not line.startswith("#")))
    assert rows[0] == ["tau", *system.states] and len(rows) == 1 + run.t.size
    assert path.read_text().startswith("# gearsym_version: ")  # the header block first
    assert float(rows[1][1]) == run.x[0, 0]  # repr round trip: no digits lost
    assert gearsym.save(run, tmp_path / "run.json").stat().st_size > 0
    assert run.save(tmp_path / "run.mat").stat().st_size > 0


def test_an_unknown_format_names_the_formats(tmp_path):
    system = gearsym.load("reference-light")
    run = gearsym.simulate(system, method="cvodes", transient=1, periods=1, samples_per_period=4)
    with pytest.raises(ValueError, match="formats: .json, .csv, .mat"):
        run.save(tmp_path / "out" / "run.xlsx")
    assert not (tmp_path / "out").exists()  # refused before anything is written
