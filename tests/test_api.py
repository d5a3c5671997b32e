"""`import gearsym` is the public API: a small surface that resolves, loads scenes by any
spelling, and exports results."""

import csv

import gearsym
import numpy as np
import pytest


def test_the_public_names_resolve():
    assert len(gearsym.__all__) == len(set(gearsym.__all__)) < 40
    for name in gearsym.__all__:
        assert getattr(gearsym, name) is not None, name


def test_load_accepts_hyphens_underscores_and_overrides():
    a = gearsym.load("reference-light")
    b = gearsym.load("reference_light", **{"lambda": 0.8})
    assert a.model_hash == b.model_hash
    assert b.values == {"lambda": 0.8} and not np.array_equal(a.p, b.p)
    with pytest.raises(gearsym.InputError, match="built-in: reference-dead-zone"):
        gearsym.load("no-such-scene")


def test_results_export_to_csv_json_and_mat(tmp_path):
    system = gearsym.load("reference-light", **{"lambda": 0.8})
    run = gearsym.simulate(system, transient=10, periods=2, samples_per_period=8)
    path = run.save(tmp_path / "run.csv")
    with open(path, newline="") as fh:
        rows = list(csv.reader(fh))
    assert rows[0] == ["tau", *system.states] and len(rows) == 1 + run.t.size
    assert float(rows[1][1]) == run.x[0, 0]  # repr round trip: no digits lost
    assert run.save(tmp_path / "run.json").stat().st_size > 0
    assert run.save(tmp_path / "run.mat").stat().st_size > 0
    with pytest.raises(ValueError, match="formats: .json, .csv, .mat"):
        run.save(tmp_path / "run.xlsx")
