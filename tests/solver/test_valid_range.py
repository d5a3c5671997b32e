"""The force law's valid range and how runs end, the same from every method (issue 14).

Reference values come from an independent method: SciPy's DOP853 at rtol 1e-12 with the
exit as a terminal event, located on its dense output by SciPy's root finder.
"""

from __future__ import annotations

import numpy as np
import pytest
from gearsym.cli import main
from gearsym.solver.integrate import METHODS, simulate
from gearsym.solver.integrate.simulate import simulate_many
from gearsym.solver.system import System


@pytest.fixture(scope="module")
def fast():
    # At omega = 50 the transient drives v past the polynomial's range |v| <= 3 within
    # the first period.
    return System.load("reference_light", omega=50.0)


def _scipy_reference(system):
    """SciPy's DOP853 at tight tolerances with its located event: the reference exit."""
    return simulate(
        system,
        method="scipy-dop853",
        rtol=1e-12,
        atol=1e-14,
        transient=10,
        periods=20,
        on_invalid="error",
    )


@pytest.fixture(scope="module")
def reference_exit(fast):
    run = _scipy_reference(fast)
    assert run.status == "invalid"
    return run.left_valid_range


@pytest.mark.parametrize("method", METHODS)
def test_every_method_stops_at_the_same_exit_in_the_transient(fast, reference_exit, method):
    run = simulate(fast, method=method, transient=10, periods=20, on_invalid="error")
    tau, state, value = run.left_valid_range
    assert run.status == "invalid", run.message
    assert state == reference_exit[1] == "v"
    assert abs(value) >= 3.0 and abs(value) < 3.01
    # the crossing interpolated on the step (Hermite, or 512 sub-intervals for CasADi)
    assert abs(tau - reference_exit[0]) < 1e-4, (tau, reference_exit[0])
    assert tau < 10 * fast.period  # in the transient, where no sample is taken


@pytest.mark.parametrize("method", ["dop853", "dopri5"])
def test_the_lockstep_engine_locates_each_points_exit(fast, method):
    # One call of the lockstep engine (one omega, other loads): each point's exit is the
    # one SciPy's DOP853 event finds for that point alone.
    systems = [fast.with_values(**{"lambda": lam}) for lam in (0.1, 0.5, 1.0)]
    runs = simulate_many(systems, method=method, transient=10, periods=20, on_invalid="error")
    for system, run in zip(systems, runs, strict=True):
        ref = _scipy_reference(system)
        assert run.status == ref.status
        if ref.left_valid_range is None:
            assert run.left_valid_range is None
        else:
            assert run.left_valid_range[1] == ref.left_valid_range[1]
            assert abs(run.left_valid_range[0] - ref.left_valid_range[0]) < 1e-4


def test_a_warned_exit_is_recorded_and_the_run_goes_on(fast, reference_exit):
    run = simulate(fast, method="dop853", transient=10, periods=20)
    assert run.status == "ok" and np.all(np.isfinite(run.x))
    assert abs(run.left_valid_range[0] - reference_exit[0]) < 1e-4


def test_a_start_outside_the_range_is_an_input_error_naming_the_state():
    far = System.load("reference_light", f1=5.0)  # the static start u = 1 + 5 > 3
    with pytest.raises(ValueError, match=r"load f_u = 5 presses u to 6, outside the backlash"):
        simulate(far)
    with pytest.raises(ValueError, match=r"the initial state v = -4"):
        simulate(System.load("reference_light"), x0=[1.0, -4.0, 0.0, 0.0])


def test_exit_codes_0_ok_2_bad_input_3_run_ended_badly(capsys):
    quick = ["--transient", "10", "--periods", "20", "--lyapunov-periods", "0"]
    assert main(["simulate", "reference-light", *quick]) == 0
    assert (
        main(["simulate", "reference-light", "--set", "omega=50", "--on-invalid", "error", *quick])
        == 3
    )
    diverging = ["--set", "xi_u_u=-0.5", "--set", "xi_v_v=-0.5", "--transient", "6"]
    for method in ("dop853", "RK45", "cvodes", "rk"):
        assert (
            main(
                [
                    "simulate",
                    "reference-light",
                    *diverging,
                    "--method",
                    method,
                    "--periods",
                    "2",
                    "--lyapunov-periods",
                    "0",
                    "--json",
                ]
            )
            == 3
        )
        assert '"status": "divergent"' in capsys.readouterr().out, method
    assert main(["simulate", "reference-light", "--set", "f1=5"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "valid range" in err
