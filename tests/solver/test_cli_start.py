"""End-to-end: initial-state control (--x0, --from-sweep/--at) in simulate and shoot, and
the minimal-period verdict of shoot."""

import json

import numpy as np
import pytest
from gearsym.cli import main

QUICK = ["--method", "cvodes", "--transient", "20", "--periods", "8", "--lyapunov-periods", "0"]


@pytest.fixture(scope="module")
def saved_sweep(tmp_path_factory):
    from gearsym.solver.sweep import sweep
    from gearsym.solver.system import System

    system = System.load("reference_light")
    result = sweep(
        system,
        "lambda",
        [0.8, 0.9],
        executor="serial",
        method="cvodes",
        transient=30,
        periods=4,
        lyapunov_periods=0,
    )
    return result, result.save(tmp_path_factory.mktemp("sw") / "sweep.json")


def test_simulate_starts_from_x0_by_position_and_by_name(capsys):
    for x0 in ("1.5,-1,0.2,0", "dv=0,du=0.2,v=-1,u=1.5"):
        assert main(["simulate", "reference-light", *QUICK, "--x0", x0, "--json"]) == 0
        data = json.loads(capsys.readouterr().out)
        assert data["initial_state"] == {
            "source": "--x0",
            "x0": {"u": 1.5, "v": -1.0, "du": 0.2, "dv": 0.0},
        }


def test_simulate_from_a_sweep_state_uses_its_state_and_value(saved_sweep, capsys):
    result, path = saved_sweep
    argv = ["simulate", "reference-light", *QUICK, "--from-sweep", str(path), "--at", "0.9"]
    assert main([*argv, "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    stored = result.points[1].x_final
    np.testing.assert_array_equal(list(data["initial_state"]["x0"].values()), stored)
    assert data["system"]["values"]["lambda"] == 0.9
    # The stored state is on the attractor: the run's first Poincare point is that state.
    assert data["integration"]["status"] == "ok"


def test_shoot_from_a_sweep_state(saved_sweep, capsys):
    _, path = saved_sweep
    assert main(["shoot", "reference-light", "--from-sweep", str(path), "--at", "0.8"]) == 0
    out = capsys.readouterr().out
    assert "period-1 orbit" in out and "guess from sweep" in out and "stable" in out


def test_shoot_reports_a_lower_period_as_what_it_is(capsys):
    # Reference: at lambda = 0.8 the attractor is the period-1 orbit (test_layers.py); a
    # period-2 search from it and one more settled guess finds no true period-2 orbit.
    argv = ["shoot", "reference-light", "--set", "lambda=0.8", "--period", "2", "--tries", "1"]
    assert main([*argv, "--json"]) == 3  # not the period asked for: exit status 3
    data = json.loads(capsys.readouterr().out)
    assert data["found_requested_period"] is False and data["requested"] == 2
    assert data["n"] == 1 and data["minimal_period"] == 1
    assert main(argv) == 3
    out = capsys.readouterr().out
    assert out.startswith("no orbit of minimal period 2 found") and "period-1 orbit" in out


@pytest.mark.parametrize(
    "extra, fragment",
    [
        (["--x0", "1,2,3"], "3 value(s), the model has 4 (u, v, du, dv)"),
        (["--x0", "u=1,v=2,du=3"], "missing dv"),
        (["--x0", "u=1,v=2,du=3,w=0"], "unknown w"),
        (["--x0", "1,2,x,4"], "every value must be a number"),
        (["--at", "0.8"], "--at needs --from-sweep"),
        (["--from-sweep", "SWEEP"], "--from-sweep needs --at"),
        (["--from-sweep", "SWEEP", "--at", "0.85"], "not a value of the sweep's lambda"),
        (["--from-sweep", "NOTASWEEP", "--at", "0.8"], "not a readable sweep file"),
        (["--from-sweep", "MISSING", "--at", "0.8"], "no such file"),
    ],
)
@pytest.mark.parametrize("command", ["simulate", "shoot"])
def test_start_errors_are_one_line(command, extra, fragment, saved_sweep, tmp_path, capsys):
    _, path = saved_sweep
    bad = tmp_path / "bad.json"
    bad.write_text('{"points": 3}')
    files = {"SWEEP": str(path), "NOTASWEEP": str(bad), "MISSING": str(tmp_path / "no.json")}
    extra = [files.get(a, a) for a in extra]
    assert main([command, "reference-light", *extra]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and fragment in err, err
