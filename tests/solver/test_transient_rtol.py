"""A looser tolerance for the transient alone (``transient_rtol``).

References: the sampled window is checked against SciPy's DOP853 at rtol 1e-12 on the
model's generated NumPy right-hand side, started from the window's first sample (an
integrator this path does not use); the joined run against the one-run path at equal
tolerances (the two differ by the steps only, within the integrator's tolerance).
"""

import json

import numpy as np
import pytest
from gearsym.cli import main
from gearsym.solver.integrate import native
from gearsym.solver.integrate.simulate import simulate, simulate_many
from gearsym.solver.system import System
from scipy.integrate import solve_ivp

pytestmark = pytest.mark.skipif(native.compiler() is None, reason="no C compiler")

RUN = dict(transient=60, periods=20, samples_per_period=8)


@pytest.fixture(scope="module")
def light():
    return System.load("reference_light", **{"lambda": 0.35})


def test_the_window_keeps_rtol_where_the_transient_was_loose(light):
    tr = simulate(light, method="dop853", rtol=1e-9, atol=1e-11, transient_rtol=1e-3, **RUN)
    assert tr.status == "ok" and tr.rtol == 1e-9 and tr.transient == 60
    assert tr.options["transient_rtol"] == 1e-3
    assert tr.options["transient_atol"] == pytest.approx(1e-11 * 1e-3 / 1e-9)
    ref = solve_ivp(
        light.rhs,
        (tr.t[0], tr.t_final),
        tr.x[:, 0],
        method="DOP853",
        rtol=1e-12,
        atol=1e-14,
        t_eval=tr.t,
    )
    window = np.abs(ref.y - tr.x).max()
    assert window < 1e-7  # the window at rtol 1e-9 (states of order 1)
    # the same window at the transient's tolerance is far off: the test can tell them apart
    loose = simulate(
        light, tr.x[:, 0], method="dop853", rtol=1e-3, atol=1e-5, **RUN | {"transient": 0}
    )
    assert np.abs(ref.y - loose.x).max() > 100 * window


def test_at_one_tolerance_it_is_the_one_run(light):
    one = simulate(light, method="dop853", **RUN)
    two = simulate(light, method="dop853", transient_rtol=1e-8, **RUN)
    assert np.abs(one.x - two.x).max() < 1e-6
    assert two.nfev > 0 and two.t[0] == one.t[0] and two.t_final == one.t_final
    np.testing.assert_array_equal(two.t, one.t)


def test_the_transient_runs_at_its_own_tolerance(light):
    # what reached the integrator, not what was recorded: the loose transient takes fewer
    # evaluations, and ends elsewhere than the tight one by more than the tight tolerance
    tight = simulate(light, rtol=1e-9, atol=1e-11, **RUN)
    loose = simulate(light, rtol=1e-9, atol=1e-11, transient_rtol=1e-4, **RUN)
    assert loose.nfev < tight.nfev and loose.nsteps < tight.nsteps
    assert 1e-7 < np.abs(loose.x[:, 0] - tight.x[:, 0]).max() < 1e-2


def test_other_families_and_the_default_method(light):
    # Reference: the one-run path of the same method (SciPy's RK45; the default, dop853)
    short = dict(transient=20, periods=4, samples_per_period=8)
    for method in ("RK45", None):
        one = simulate(light, method=method, rtol=1e-9, atol=1e-11, **short)
        two = simulate(light, method=method, rtol=1e-9, atol=1e-11, transient_rtol=1e-9, **short)
        assert two.method == one.method and np.abs(one.x - two.x).max() < 1e-6
    with pytest.raises(ValueError, match="transient_rtol is for the adaptive methods"):
        simulate(light, method="rk4", transient_rtol=1e-6, **short)


def test_an_exit_from_the_valid_range_in_the_transient_is_kept(light):
    # the polynomial backlash holds for |u| <= 3: a start at u = 2.9 moving outward leaves it
    x0 = np.array([2.9, 0.0, 2.0, 0.0])
    one = simulate(light, x0, **RUN)
    two = simulate(light, x0, transient_rtol=1e-6, **RUN)
    assert one.left_valid_range is not None and one.left_valid_range[0] < one.t[0]
    assert two.status == "ok" and two.left_valid_range[1] == one.left_valid_range[1]
    assert two.left_valid_range[0] == pytest.approx(one.left_valid_range[0], rel=1e-3)
    stop = simulate(light, x0, transient_rtol=1e-6, on_invalid="error", **RUN)
    assert stop.status == "invalid" and np.all(np.isnan(stop.x))
    assert simulate(light, x0, on_invalid="error", **RUN).status == "invalid"


def test_many_points_at_once_match_one_at_a_time(light):
    systems = [light.with_values(damping_ratio=z) for z in (0.04, 0.06, 0.08)]
    many = simulate_many(systems, method="dop853", transient_rtol=1e-5, **RUN)
    for s, tr in zip(systems, many, strict=True):
        one = simulate(s, method="dop853", transient_rtol=1e-5, **RUN)
        assert tr.options["transient_rtol"] == 1e-5
        assert np.abs(one.x - tr.x).max() < 1e-6


def test_a_transient_that_fails_fails_the_run(light):
    tr = simulate(light, method="dop853", transient_rtol=1e-6, bound=1e-3, **RUN)
    assert tr.status == "divergent" and "passed" in tr.message
    assert tr.rtol == 1e-8 and tr.x.shape == (light.n, 20 * 8)
    assert np.all(np.isnan(tr.x))


def test_an_unusable_tolerance_is_refused(light):
    for bad in (0.5, 1e-16, float("nan"), "1e-6", True):
        with pytest.raises(ValueError, match="transient_rtol must be a number in"):
            simulate(light, transient_rtol=bad, **RUN)


def test_the_cli_names_it_and_records_it(tmp_path, capsys):
    sweep = ["sweep", "--param", "lambda", "--range", "0.3:0.4:2", "--method", "rk4"]
    for cmd in (["simulate"], ["simulate", "--method", "rk4"], sweep):
        for bad in ("-1", "1e-15") if len(cmd) == 1 else ("0.001",):
            assert main([cmd[0], "reference-light", *cmd[1:], "--transient-rtol", bad]) == 2
            err = capsys.readouterr().err.strip().splitlines()
            assert len(err) == 1 and f"--transient-rtol {bad}" in err[0]
    out = tmp_path / "s"
    argv = ["sweep", "reference-light", "--param", "lambda", "--range", "0.3:0.4:2"]
    argv += ["--independent", "--quiet", "--no-figure", "--transient", "50", "--periods", "8"]
    assert main([*argv, "--transient-rtol", "1e-6", "--out", str(out)]) == 0
    settings = json.loads((out / "sweep.json").read_text())["settings"]
    assert settings["transient_rtol"] == 1e-6
