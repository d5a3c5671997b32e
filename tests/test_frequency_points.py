"""NUM is the number of points for every method of the frequency response (issue 25,
point 8).  Reference: the promise of `--param`'s help and of `frequency_response`'s
docstring -- a branch without folds returns NUM points at linspace(START, STOP, NUM);
integration NUM frequencies up and NUM down.  The scene is reference-linear over
omega in [0.3, 1.0]: a linear oscillator's response has no folds (asserted below)."""

from __future__ import annotations

import json

import numpy as np
import pytest
from gearsym.cli import main
from gearsym.solver.sweep.frequency import frequency_response
from gearsym.solver.system import System

NUM = 40
GRID = np.linspace(0.3, 1.0, NUM)


@pytest.mark.parametrize("method", ["hb", "shooting", "integration"])
def test_num_points_without_folds(method):
    system = System.load("reference_linear")
    resp = frequency_response(system, "omega", 0.3, 1.0, points=NUM, methods=(method,))
    curves = resp.curves
    assert len(curves) == (2 if method == "integration" else 1)
    for curve in curves:
        assert not [e for e in curve.events if e.kind == "fold"]
        values = np.sort(np.asarray(curve.values, float))
        np.testing.assert_allclose(values, GRID, rtol=0, atol=1e-12)


def test_step_sets_the_continuation_not_the_count():
    # a first step ten times smaller than the default still returns the grid's values
    system = System.load("reference_linear")
    resp = frequency_response(
        system, "omega", 0.3, 1.0, points=NUM, methods=("hb",), step=0.7 / 390
    )
    np.testing.assert_allclose(resp.curves[0].values, GRID, rtol=0, atol=1e-12)


def test_fold_points_added_to_the_grid():
    # reference-light folds (the backlash's overhang): each of its k + 1 monotonic pieces
    # holds the grid's values in its span, plus the k turning points, so more than NUM
    system = System.load("reference_light")
    (curve,) = frequency_response(
        system, "omega", 0.3, 1.0, points=NUM, methods=("hb",), harmonics=12
    ).curves
    folds = [e for e in curve.events if e.kind == "fold"]
    assert folds
    on_grid = np.isclose(np.asarray(curve.values)[:, None], GRID[None, :], atol=1e-12)
    assert set(np.nonzero(on_grid.any(axis=0))[0]) == set(range(NUM))  # every value covered
    assert (~on_grid.any(axis=1)).sum() == len(folds)  # the turning points, one per fold


def test_cli_num_points(capsys, tmp_path):
    argv = ["frequency-response", "reference-linear", f"--param=omega=0.3:1:{NUM}"]
    code = main([*argv, "--method=all", "--json", "--no-figure", f"--out={tmp_path}"])
    out = capsys.readouterr()
    assert code == 0, out.err
    records = [json.loads(line) for line in out.out.splitlines()]
    counts = {m: sum(r["method"] == m for r in records) for m in ("hb", "shooting")}
    assert counts == {"hb": NUM, "shooting": NUM}
    assert sum(r["method"] == "integration" for r in records) == 2 * NUM


@pytest.mark.parametrize(
    ("step", "message"),
    [("0", "--step 0: give a step in (0, 0.7]"), ("1e-9", "the continuation would take")],
)
def test_cli_step_refused(capsys, tmp_path, step, message):
    argv = ["frequency-response", "reference-linear", "--param=omega=0.3:1:40"]
    code = main([*argv, f"--step={step}", f"--out={tmp_path}"])
    err = capsys.readouterr().err
    assert code == 2 and message in err and len(err.strip().splitlines()) == 1
