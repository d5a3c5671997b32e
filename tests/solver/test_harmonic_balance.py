"""Harmonic balance (AFT) and Hill's stability against closed forms and shooting."""

import numpy as np
import pytest
from gearsym.solver.periodic import shoot
from gearsym.solver.periodic.harmonic_balance import (
    HarmonicBalance,
    HarmonicBalanceError,
    harmonic_balance,
)
from gearsym.solver.system import System
from scipy.linalg import expm

from .conftest import HERE
from .test_simulate import closed_form_steady_state

DUFFING = HERE / "duffing_model.py"


def test_linear_limit_equals_the_closed_form_steady_state(linear_system):
    # Reference: the complex-amplitude steady state of the forced damped linear system
    # (tests/solver/test_simulate.py); harmonic balance is exact on it with H >= 1, and
    # Hill's multipliers are exp(eig(A) T) (constant coefficients).
    sol = harmonic_balance(linear_system, harmonics=3)
    tau = np.linspace(0.0, linear_system.period, 37)
    np.testing.assert_allclose(
        sol.at(tau), closed_form_steady_state(linear_system, tau), rtol=0, atol=1e-8
    )
    A = linear_system.jacobian(0.0, np.zeros(linear_system.n))
    expected = np.sort_complex(np.linalg.eigvals(expm(A * linear_system.period)))
    np.testing.assert_allclose(np.sort_complex(sol.floquet.multipliers), expected, atol=1e-8)
    assert sol.floquet.stable and sol.tail_share() < 1e-10


@pytest.mark.parametrize(("omega", "B"), [(0.8, 0.2), (1.5, 0.3), (2.0, 0.01)])
def test_one_harmonic_duffing_against_its_closed_form(omega, B):
    # Reference: the one-term harmonic balance of x'' + a x + c x^3 = B cos(w t) (undamped),
    # x = A cos(w t) with (a - w^2) A + 3/4 c A^3 = B (Nayfeh and Mook 1979, "Nonlinear
    # Oscillations", 4.1); at B -> 0 it is the backbone w^2 = a + 3/4 c A^2.
    a, c = 1.0, 0.5
    system = System.load(DUFFING, a=a, c=c, k=0.0, B=B, omega=omega)
    sol = harmonic_balance(
        system, np.array([[0.0, B / (a - omega**2), 0.0], [0.0] * 3]), harmonics=1, stability=False
    )
    A = sol.coefficients[0, 1]
    roots = np.roots([0.75 * c, 0.0, a - omega**2, -B])
    exact = roots[np.argmin(np.abs(roots - A))]
    assert abs(exact.imag) < 1e-12 and abs(A - exact.real) < 1e-10 * max(1.0, abs(A))
    assert abs(sol.coefficients[0, 2]) < 1e-12  # no sine part without damping


def test_backbone_is_a_solution_of_the_unforced_one_harmonic_balance():
    a, c, A = 1.0, 0.5, 1.3
    omega = np.sqrt(a + 0.75 * c * A**2)
    system = System.load(DUFFING, a=a, c=c, k=0.0, B=0.0, omega=omega)
    problem = HarmonicBalance(system, 1)
    X = np.array([[0.0, A, 0.0], [0.0, 0.0, -omega * A]])
    R, _ = problem.residual(X, system.p)
    assert np.max(np.abs(R)) < 1e-12


def test_jacobian_is_the_derivative_of_the_residual():
    # Reference: central finite differences of the residual (an independent route).
    system = System.load(DUFFING, a=1.0, c=0.5, k=0.1, B=0.4, omega=1.3)
    problem = HarmonicBalance(system, 4)
    X = np.random.default_rng(2).normal(size=(2, 9)) * 0.3
    _, Jac = problem.residual(X, system.p)
    h = 1e-6
    fd = np.empty_like(Jac)
    for j in range(X.size):
        e = np.zeros(X.size)
        e[j] = h
        up = problem.residual(X + e.reshape(X.shape), system.p, jacobian=False)[0]
        dn = problem.residual(X - e.reshape(X.shape), system.p, jacobian=False)[0]
        fd[:, j] = (up - dn).ravel() / (2 * h)
    np.testing.assert_allclose(Jac, fd, rtol=0, atol=1e-8)


def _hardening(omega, k=0.1, B=0.3):
    return System.load(DUFFING, a=1.0, c=0.1, k=k, B=B, omega=omega)


def _one_harmonic_branches(a, c, k, B, w):
    """The damped one-term balance of x'' + k x' + a x + c x^3 = B cos(w t), x = p cos +
    q sin: [(a - w^2 + 3/4 c A^2)^2 + (k w)^2] A^2 = B^2, a cubic in A^2 (Nayfeh and Mook
    1979, 4.1.4); each real root gives (p, q) by a 2 x 2 solve.  Lowest amplitude first."""
    e, g = a - w**2, 0.75 * c
    roots = np.roots([g**2, 2 * e * g, e**2 + (k * w) ** 2, -(B**2)])
    out = []
    for A2 in np.sort(roots[np.abs(roots.imag) < 1e-12].real):
        al = e + g * A2
        p, q = np.linalg.solve([[al, k * w], [-k * w, al]], [B, 0.0])
        out.append(np.array([[0.0, p, q], [0.0, w * q, -w * p]]))
    return out


@pytest.mark.parametrize(("branch", "stable"), [(0, True), (1, False), (2, True)])
def test_duffing_against_shooting_on_stable_and_unstable_branches(branch, stable):
    # Reference: Newton shooting with its monodromy (solver/periodic/shooting.py), an
    # independent method.  Inside the hysteresis band of this hardening oscillator
    # (omega = 1.5, light damping) three period-1 solutions coexist, the middle one
    # unstable; the damped one-harmonic balance starts harmonic balance on each.
    system = _hardening(1.5, k=0.05, B=0.5)
    starts = _one_harmonic_branches(1.0, 0.1, 0.05, 0.5, 1.5)
    assert len(starts) == 3
    sol = harmonic_balance(system, starts[branch], harmonics=15)
    assert sol.residual < 1e-10 and sol.tail_share() < 1e-8
    orbit = shoot(system, sol.state(0.0), 1, tol=1e-12)
    assert np.max(np.abs(sol.state(0.0) - orbit.x0)) < 1e-6
    got = np.sort_complex(sol.floquet.multipliers)
    np.testing.assert_allclose(got, np.sort_complex(orbit.floquet.multipliers), atol=1e-6)
    assert sol.floquet.stable == orbit.floquet.stable == stable
    assert sol.floquet.liouville_error < 1e-8  # the exponents' sum is the mean trace


def test_hill_multipliers_match_the_monodromy_along_the_response():
    for omega in (0.6, 1.0, 1.2, 2.5):
        system = _hardening(omega)
        sol = harmonic_balance(system, harmonics=15)
        orbit = shoot(system, sol.state(0.0), 1, tol=1e-12)
        np.testing.assert_allclose(
            np.sort_complex(sol.floquet.multipliers),
            np.sort_complex(orbit.floquet.multipliers),
            atol=1e-6,
        )


@pytest.mark.parametrize(("omega", "lam"), [(0.3, 0.8), (0.5, 0.4), (0.5, 0.8), (0.9, 0.8)])
def test_reference_model_against_shooting_at_period_one_points(omega, lam):
    # The reference DI-SO model (polynomial backlash, stated values) at several forcing
    # frequencies where its motion is period-1; reference: shooting, an independent method.
    system = System.load("reference_light", omega=omega, **{"lambda": lam})
    sol = harmonic_balance(system, harmonics=24)
    assert sol.tail_share() < 1e-6
    orbit = shoot(system, sol.state(0.0), 1, tol=1e-12)
    assert orbit.minimal_period == 1
    assert np.max(np.abs(sol.state(0.0) - orbit.x0)) < 1e-6
    np.testing.assert_allclose(
        np.sort_complex(sol.floquet.multipliers),
        np.sort_complex(orbit.floquet.multipliers),
        atol=1e-6,
    )
    assert sol.floquet.stable == orbit.floquet.stable


def test_bad_sizes_are_refused():
    system = _hardening(1.0)
    with pytest.raises(ValueError, match="harmonics must be >= 0"):
        HarmonicBalance(system, -1)
    with pytest.raises(ValueError, match="samples"):
        HarmonicBalance(system, 10, samples=16)
    with pytest.raises(HarmonicBalanceError, match="did not converge"):
        harmonic_balance(system, np.full((2, 3), 1e6), harmonics=1, max_iter=2)


def test_continuation_through_the_hysteresis_band_of_a_hardening_duffing():
    # Pseudo-arclength continuation in omega from below resonance to above the band: the
    # branch bends back at two folds, the segment between them is unstable, and Hill's
    # multipliers along the whole branch (stable and unstable points) equal the
    # eigenvalues of the monodromy integrated at the harmonic-balance state (reference:
    # the variational equations of solver/periodic/flow.py, an independent method).
    from gearsym.solver.periodic import StroboscopicMap
    from gearsym.solver.periodic.hb_continuation import continue_hb

    system = _hardening(0.8, k=0.05, B=0.5)
    branch = continue_hb(system, "omega", 0.8, 2.6, harmonics=16)
    folds = [b for b in branch.bifurcations if b.kind == "fold"]
    assert len(folds) == 2 and folds[0].value > folds[1].value
    lo, hi = folds[0].index, folds[1].index
    assert not branch.stable[lo:hi].any() and branch.stable[:lo].all()
    assert branch.stable[hi:].all() and branch.values[-1] == 2.6
    # at each fold a multiplier is +1, by Hill's method and by the monodromy of a time
    # integration from the located state (the record's evidence)
    for b in folds:
        assert abs(b.multiplier - 1.0) < 1e-4, b.multiplier
        assert abs(b.evidence["max_monodromy_multiplier"] - 1.0) < 1e-6, b.evidence
    # the folds are converged in H: 12 harmonics give the same values
    again = continue_hb(system, "omega", 0.8, 2.6, harmonics=12)
    np.testing.assert_allclose(
        [b.value for b in again.bifurcations], [b.value for b in folds], rtol=0, atol=1e-8
    )
    problem = HarmonicBalance(system, 16)
    smap = StroboscopicMap(system, 1)
    for point in branch.points[::40]:
        p = system.parameters_with(omega=point.value)
        x0 = problem.time_series(point.coefficients, np.array([0.0]))[:, 0]
        _, M, _ = smap.jacobian(x0, p)
        np.testing.assert_allclose(
            np.sort_complex(point.multipliers), np.sort_complex(np.linalg.eigvals(M)), atol=1e-6
        )
    records = branch.records()
    assert set(records[0]) == {"omega", "stable", "stability", "x"}
    assert set(records[0]["x"]) == {"mean", "amplitude", "rms", "min", "max"}


def test_integration_sweeps_in_the_phase_agree_with_harmonic_balance():
    # The up and down stepped sweeps run in one lockstep group in the excitation phase
    # s = omega tau.  Reference: harmonic balance solved afresh at sampled frequencies from
    # the sweep's own Poincare state (an independent method): mean and RMS (the samples'
    # trapezoid rule is exact on a band-limited signal) agree to 1e-6; and the up sweep
    # jumps where harmonic-balance continuation puts the fold at the end of the overhang.
    from gearsym.solver.periodic.hb_continuation import continue_hb
    from gearsym.solver.sweep.frequency import frequency_response

    system = System.load("reference_light")
    resp = frequency_response(system, "omega", 0.5, 0.7, points=41, methods=("integration",))
    up, down = resp.curves
    assert up.details["direction"] == "up" and down.details["direction"] == "down"
    checked = 0
    for k in range(0, len(up.values), 8):
        if up.stats["u"]["poincare_spread"][k] > 1e-8:
            continue  # not period-1 here
        w = float(up.values[k])
        state = np.array(up.details["poincare"][k][-1])
        sol = harmonic_balance(system.with_values(omega=w), state, harmonics=20)
        for c in ("u", "v"):
            assert abs(sol.mean(c) - up.stats[c]["mean"][k]) < 1e-6
            assert abs(sol.rms(c) - up.stats[c]["rms"][k]) < 1e-6
        checked += 1
    assert checked >= 3
    amp = up.stats["u"]["amplitude"]
    jump = int(np.argmax(np.abs(np.diff(amp))))
    branch = continue_hb(system, "omega", 0.5, 0.7)
    folds = [b.value for b in branch.bifurcations if b.kind == "fold"]
    step = up.values[1] - up.values[0]
    assert any(up.values[jump] - 1e-9 <= f <= up.values[jump + 1] + 1e-9 for f in folds), (
        up.values[jump],
        folds,
        step,
    )
    # just below that fold the down sweep is on the upper branch, the up sweep on the lower
    d = int(np.argmin(np.abs(down.values - up.values[jump])))
    assert abs(down.stats["u"]["amplitude"][d] - amp[jump]) > 0.1


def test_both_ways_of_picking_hills_exponents_agree():
    # The fast path (eigenvalues in the strip |Im| <= omega/2n, accepted only when their
    # sum passes Liouville's check) against the eigenvector-symmetry criterion on the
    # three branches of the hardening Duffing oscillator (the middle one unstable).
    import sys

    hill_module = sys.modules["gearsym.solver.periodic.hill"]
    system = _hardening(1.5, k=0.05, B=0.5)
    for start in _one_harmonic_branches(1.0, 0.1, 0.05, 0.5, 1.5):
        sol = harmonic_balance(system, start, harmonics=15)
        problem = HarmonicBalance(system, 15)
        A = problem.hill_matrix(sol.coefficients, system.p, 8)
        period = system.period
        slow = hill_module._symmetric(A, 2, 17, 8, period)
        # copies shifted by i k omega are one exponent: compare the multipliers
        np.testing.assert_allclose(
            np.sort_complex(np.exp(sol.exponents * period)),
            np.sort_complex(np.exp(slow * period)),
            atol=1e-9,
        )
        # a wrong trace makes the fast path decline (and the caller fall back)
        assert hill_module._strip(np.linalg.eigvals(A), 2, 1.5, period, 1e3) is None


def test_harmonics_are_raised_until_the_tail_is_small():
    # the dead zone's kinks need many harmonics: from H = 4 the share carried by the top
    # quarter is above 1e-4 (docs/analysis.md); raising H doubles it until below
    system = System.load("reference_dead_zone", omega=0.3350715452962742, **{"lambda": 0.1})
    sol = harmonic_balance(system, harmonics=4, tail=1e-4, stability=False)
    assert sol.harmonics > 4 and sol.tail_share() <= 1e-4
    assert (
        harmonic_balance(
            system, sol.coefficients, harmonics=sol.harmonics // 2, stability=False
        ).tail_share()
        > 1e-4
    )
    with pytest.raises(ValueError, match="tail must be a positive share"):
        harmonic_balance(system, harmonics=4, tail=0.0)
