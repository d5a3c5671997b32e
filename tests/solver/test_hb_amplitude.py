"""Harmonic-balance amplitudes and extremes read off the trigonometric polynomial (issue 27,
point 5), against closed forms."""

import numpy as np
from gearsym.solver.periodic.aft import HarmonicBalance
from gearsym.solver.periodic.harmonic_balance import harmonic_balance
from gearsym.solver.system import System

from .conftest import HERE
from .test_simulate import closed_form_steady_state


def _complex_amplitudes(system):
    """Static deflection and complex amplitude of each coordinate of the forced damped
    linear oscillator (the closed form of tests/solver/test_simulate.py, read at two
    phases: u(0) = s + Re X, u(pi / (2 w)) = s - Im X)."""
    tau = np.array([0.0, 0.5 * np.pi / system.omega, np.pi / system.omega])
    x = closed_form_steady_state(system, tau)[: len(system.coordinates)]
    static = 0.5 * (x[:, 0] + x[:, 2])
    return static, (x[:, 0] - static) - 1j * (x[:, 1] - static)


def test_linear_amplitude_and_extremes_equal_the_closed_form(linear_system):
    # Reference: u = s + Re(X e^{i w tau}), so the half peak-to-peak is |X| and the
    # extremes s -+ |X|.  A 512-phase grid was 1.9e-5 off (issue 27); the refined extrema
    # are exact to rounding.
    sol = harmonic_balance(linear_system, harmonics=3, stability=False)
    static, X = _complex_amplitudes(linear_system)
    for i, c in enumerate(linear_system.coordinates):
        lo, hi = sol.extremes(c)
        scale = max(1.0, abs(static[i]))
        assert abs(sol.amplitude(c) - abs(X[i])) < 1e-12 * scale, (c, sol.amplitude(c), X[i])
        assert abs(hi - (static[i] + abs(X[i]))) < 1e-12 * scale
        assert abs(lo - (static[i] - abs(X[i]))) < 1e-12 * scale
    # the same numbers off the samples of a grid are a coarser reading: 512 phases
    y = sol.at(np.linspace(0, linear_system.period, 512, endpoint=False))[0]
    assert abs((y.max() - y.min()) / 2 - abs(X[0])) > 1e-9


def test_frequency_response_keeps_exact_extremes_of_the_linear_model(linear_system):
    # Every point of the harmonic-balance curve against the closed form at its frequency;
    # the saved records keep the minimum and maximum of each coordinate.
    from gearsym.solver.sweep.frequency import frequency_response

    resp = frequency_response(linear_system, "omega", 0.4, 0.6, points=8, harmonics=3)
    curve = resp.curves[0]
    for k in range(0, len(curve.values), 3):
        s = linear_system.with_values(omega=float(curve.values[k]))
        static, X = _complex_amplitudes(s)
        for i, c in enumerate(s.coordinates):
            st = curve.stats[c]
            assert abs(st["amplitude"][k] - abs(X[i])) < 1e-10
            assert abs(st["max"][k] - static[i] - abs(X[i])) < 1e-10
            assert abs(st["min"][k] - static[i] + abs(X[i])) < 1e-10
    rec = curve.records()[0]
    assert {"min", "max"} <= set(rec["u"]) and rec["u"]["max"] > rec["u"]["min"]
    columns, rows = resp.to_table()
    assert {"u_min", "u_max", "v_min", "v_max"} <= set(columns)
    assert len(rows[0]) == len(columns)


def test_extrema_of_a_sharp_polynomial_against_a_dense_reading():
    # Reference: x(s) = sum_k cos(k s) / k^2 (k <= 40), whose maximum H_2(40) = sum 1/k^2
    # sits at s = 0 and whose minimum, -pi^2/12 in the limit, is found by a 2^16-phase
    # grid refined by golden section (an independent route); a sharp peak that a coarse
    # grid misses by O(h).
    from scipy.optimize import minimize_scalar

    system = System.load(HERE / "duffing_model.py")
    H = 40
    problem = HarmonicBalance(system, H)
    X = np.zeros((1, 2 * H + 1))
    X[0, 1::2] = 1.0 / np.arange(1, H + 1) ** 2
    lo, hi = problem.extrema(X)
    assert abs(hi[0] - np.sum(1.0 / np.arange(1, H + 1) ** 2)) < 1e-13

    def x(s):
        return float(problem.time_series(X, np.array([s]))[0, 0])

    s = 2 * np.pi * np.arange(1 << 16) / (1 << 16)
    j = int(np.argmin(problem.time_series(X, s)[0]))
    h = 2 * np.pi / (1 << 16)
    best = minimize_scalar(
        x, bounds=(s[j] - h, s[j] + h), method="bounded", options={"xatol": 1e-12}
    )
    assert abs(lo[0] - best.fun) < 1e-13
