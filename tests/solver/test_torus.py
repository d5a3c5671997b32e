"""Torus evidence against sequences whose rotation number is known in closed form.

References: the steady state of a linear damped oscillator under two harmonic forces
(superposition of the two frequency responses); Laskar, Physica D 67 (1993) 257, for the
refined frequency (NAFF); the logistic map at r = 4 (Ulam and von Neumann: chaotic, with
a flat spectrum).
"""

import json

import numpy as np
import pytest
from gearsym.solver.analysis.torus import torus_evidence

SQRT2 = np.sqrt(2.0)


def two_force_oscillator(K, zeta=0.05):
    """x'' + 2 zeta x' + x = cos(tau) + cos(sqrt(2) tau), steady state sampled at
    tau = 2 pi k: x = sum_w Re[exp(i w tau) / (1 - w^2 + 2 i zeta w)], x' its derivative."""
    tau = 2 * np.pi * np.arange(K)
    x, v = np.zeros(K), np.zeros(K)
    for w in (1.0, SQRT2):
        e = np.exp(1j * w * tau) / (1 - w * w + 2j * zeta * w)
        x, v = x + e.real, v + (1j * w * e).real
    return np.vstack([x, v])


def distorted_circle(rho, K):
    """An invariant circle of a circle map, seen through a nonlinear change of phase and
    of coordinates: every coordinate holds only the lines m rho (mod 1)."""
    theta = 2 * np.pi * rho * np.arange(K)
    phase = theta + 0.3 * np.sin(theta)
    return np.vstack(
        [np.cos(phase) + 0.2 * np.cos(2 * phase), np.sin(phase) + 0.1 * np.sin(phase) ** 2]
    )


def logistic(r, n, x0=0.3, transient=1000):
    x, out = x0, np.empty(n)
    for i in range(transient + n):
        x = r * x * (1.0 - x)
        if i >= transient:
            out[i - transient] = x
    return out


@pytest.mark.parametrize("K", [1000, 4000])
def test_two_incommensurate_forces_give_the_closed_form_rotation_number(K):
    # the section turns by frac(sqrt 2) per forcing period; the cos(tau) part is a fixed
    # point of the section and drops with the mean
    ev = torus_evidence(two_force_oscillator(K), period=2 * np.pi)
    rho = SQRT2 - 1
    assert abs(ev.rotation_number - rho) < ev.tolerance
    assert abs(ev.rotation_number - rho) < 1e-8  # NAFF on a clean line
    assert ev.tolerance == pytest.approx(0.1 / K)  # the halves agree far below it
    assert ev.nearest_rational[:2] == (12, 29)  # 0.41379..., 4.2e-4 away
    assert ev.incommensurate and ev.is_torus
    assert ev.explained_share > 0.99
    f1, f2 = ev.base_frequencies
    assert f1 == pytest.approx(1 / (2 * np.pi)) and f2 == pytest.approx(rho / (2 * np.pi))
    assert {p.m for p in ev.peaks} == {1}


def test_a_short_record_cannot_tell_sqrt2_from_12_over_29():
    # 200 periods: tol = 0.1/200 = 5e-4 exceeds |frac(sqrt 2) - 12/29| = 4.2e-4
    ev = torus_evidence(two_force_oscillator(200))
    assert not ev.incommensurate and not ev.is_torus
    assert ev.nearest_rational[:2] == (12, 29)


def test_distorted_invariant_circle_is_a_torus():
    golden = (np.sqrt(5) - 1) / 2  # folded into (0, 1/2]: 1 - golden = 0.381966...
    ev = torus_evidence(distorted_circle(golden, 2000))
    assert abs(ev.rotation_number - (1 - golden)) < ev.tolerance
    assert ev.is_torus and ev.explained_share > 0.999
    assert all(p.m is not None for p in ev.peaks)
    assert {p.m for p in ev.peaks} >= {1, 2, 3}  # the distortion's harmonics, explained


def test_near_resonance_is_not_called_incommensurate():
    # rho = 12/29 + 2e-5 over 1000 periods drifts 0.02 cycle against 12/29: no torus yet
    ev = torus_evidence(distorted_circle(12 / 29 + 2e-5, 1000))
    assert ev.nearest_rational[:2] == (12, 29)
    assert ev.explained_share > 0.99 and not ev.incommensurate and not ev.is_torus


@pytest.mark.parametrize("p", [1, 2])
def test_period_five_is_commensurate(p):
    ev = torus_evidence(distorted_circle(p / 5, 1000))
    assert ev.nearest_rational[1] == 5
    assert ev.rotation_number == pytest.approx(ev.nearest_rational[0] / 5, abs=1e-8)
    assert ev.nearest_rational[0] in (1, 2)
    assert not ev.incommensurate and not ev.is_torus


def test_chaotic_logistic_map_is_not_a_torus():
    ev = torus_evidence(logistic(4.0, 4000))
    assert ev.explained_share < 0.1  # a flat spectrum: the harmonics of one line hold ~1 %
    assert not ev.is_torus
    assert any(p.m is None for p in ev.peaks)


def test_describe_is_json_and_complete():
    ev = torus_evidence(two_force_oscillator(1000), period=2 * np.pi)
    d = json.loads(json.dumps(ev.describe(), allow_nan=False))
    assert d["is_torus"] is True and d["incommensurate"] is True
    assert d["nearest_rational"]["q"] == 29
    assert d["rotation_number"] == ev.rotation_number
    assert d["peaks"][0]["m"] == 1 and d["peaks"][0]["coordinate"] in (0, 1)
    assert d["samples"] == 1000 and d["period"] == pytest.approx(2 * np.pi)


def test_a_constant_row_is_ignored_and_points_may_be_one_coordinate():
    pts = distorted_circle((np.sqrt(5) - 1) / 2, 1000)
    with_fixed = np.vstack([pts, np.full(1000, 3.0)])
    a, b = torus_evidence(with_fixed), torus_evidence(pts[0])
    assert a.is_torus and b.is_torus
    assert a.rotation_number == pytest.approx(b.rotation_number, abs=1e-8)
    assert {p.coordinate for p in a.peaks} == {0, 1}


@pytest.mark.parametrize(
    "points, words",
    [
        (np.ones((2, 500)), "constant"),
        (np.zeros((500, 2)) + np.arange(2), "shape"),  # transposed: K = 2
        (np.zeros((2, 3, 200)), "shape"),
        (np.r_[np.arange(200.0), np.inf], "nan or inf"),
    ],
)
def test_bad_points_fail_in_one_line(points, words):
    with pytest.raises(ValueError, match=words) as info:
        torus_evidence(points)
    assert "\n" not in str(info.value)


def test_bad_options_fail_in_one_line():
    pts = distorted_circle(0.3, 300)
    for kwargs in ({"period": 0.0}, {"max_denominator": 0}, {"tolerance_bins": -1.0}):
        with pytest.raises(ValueError, match="torus_evidence"):
            torus_evidence(pts, **kwargs)


def test_line_amplitudes_are_in_the_coordinates_units():
    # x's line at frac(sqrt 2) has the closed-form amplitude |1 / (1 - 2 + 2 i zeta sqrt 2)|
    ev = torus_evidence(two_force_oscillator(2000, zeta=0.05))
    (line,) = [p for p in ev.peaks if p.coordinate == 0]
    assert line.amplitude == pytest.approx(1 / abs(-1 + 2j * 0.05 * SQRT2), rel=1e-3)


def test_rotation_number_is_the_generator_not_the_strongest_line():
    # the second harmonic dominates; rho itself is the line whose multiples explain all
    golden = (np.sqrt(5) - 1) / 2
    theta = 2 * np.pi * golden * np.arange(2000)
    ev = torus_evidence(np.cos(2 * theta) + 0.3 * np.cos(theta) + 0.2 * np.cos(3 * theta))
    assert ev.rotation_number == pytest.approx(1 - golden, abs=1e-8)
    assert ev.is_torus and {p.m for p in ev.peaks} == {1, 2, 3}
