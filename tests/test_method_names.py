"""Integrator names that differ by more than case (issue 25, point 8): SciPy's DOP853 is
``scipy-dop853``; the old name ``DOP853`` is refused, naming the new one and the compiled
``dop853``, from the API and from the command line (one line, exit 2)."""

from __future__ import annotations

import pytest
from gearsym.cli import main
from gearsym.solver.integrate import METHODS, get_method

REFUSAL = (
    "method 'DOP853' is now 'scipy-dop853' (the SciPy integrator; 'dop853' is the compiled one)"
)


def test_no_two_names_differ_by_case_only():
    assert len({m.lower() for m in METHODS}) == len(METHODS)


def test_new_name_runs_scipy_dop853():
    record = get_method("scipy-dop853")
    assert (record.family, record.engine, record.order) == ("scipy", "DOP853", 8)
    assert get_method("dop853").family == "native"


def test_old_name_refused_by_the_api():
    with pytest.raises(ValueError) as err:
        get_method("DOP853")
    assert str(err.value) == REFUSAL


def test_old_name_refused_by_the_api_simulate():
    from gearsym.solver.integrate import simulate
    from gearsym.solver.system import System

    with pytest.raises(ValueError, match="is now 'scipy-dop853'"):
        simulate(System.load("reference_light"), method="DOP853", transient=0, periods=1)


@pytest.mark.parametrize("command", ["simulate", "sweep"])
def test_old_name_refused_by_the_cli(command, capsys):
    argv = [command, "reference-light", "--method", "DOP853"]
    if command == "sweep":
        argv += ["--param", "lambda", "--range", "0:1:3"]
    with pytest.raises(SystemExit) as done:
        main(argv)
    assert done.value.code == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "Traceback" not in err
    assert REFUSAL in err
