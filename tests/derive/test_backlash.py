"""Backlash models and the dead-zone fit."""

import numpy as np
import pytest
import sympy as sp
from gearsym.derive import DeadZone, LinearContact, SmoothDeadZone, dead_zone, fit_dead_zone

# Reference: the study's printed polynomial, g(x) = 0.0017x^7 - 0.0366x^5 + 0.2833x^3 - 0.1555x.
STUDY = (-0.1555, 0.2833, -0.0366, 0.0017)


def test_default_fit_reproduces_the_study_printed_digits():
    fit = fit_dead_zone()  # order 7, range 3, step 0.01
    assert fit.samples == 601
    assert tuple(round(c, 4) for c in fit.coefficients) == STUDY


def test_fit_valid_range_and_negative_slope_at_origin():
    fit = fit_dead_zone()
    assert fit.valid_range == 3.0
    assert fit.coefficients[0] < 0  # SEED: the polynomial's slope at 0 is negative


def test_order_one_continuous_fit_matches_closed_form():
    # Closed form: a = int_1^A x (x-1) dx / int_0^A x^2 dx = (A^3/3 - A^2/2 + 1/6) / (A^3/3).
    for a in (1.5, 3.0, 7.0):
        fit = fit_dead_zone(1, a, None)
        expected = (a**3 / 3 - a**2 / 2 + 1 / 6) / (a**3 / 3)
        assert fit.coefficients[0] == pytest.approx(expected, rel=1e-13)


def test_sampled_fit_converges_to_continuous_fit():
    # Riemann sums converge to the integrals: the sampled normal equations tend to the
    # continuous ones at rate O(h) (kinks of the dead zone), checked on two steps.
    cont = np.array(fit_dead_zone(7, 3.0, None).coefficients)
    e1 = np.max(np.abs(np.array(fit_dead_zone(7, 3.0, 0.01).coefficients) - cont))
    e2 = np.max(np.abs(np.array(fit_dead_zone(7, 3.0, 0.001).coefficients) - cont))
    assert e2 < e1 / 5


def test_high_order_fit_is_well_conditioned_and_accurate():
    fit = fit_dead_zone(21, 3.0, 0.001)
    assert fit.max_error() < fit_dead_zone(7, 3.0, 0.001).max_error()


@pytest.mark.parametrize("bad", [0, 2, -3])
def test_even_or_nonpositive_order_is_refused(bad):
    with pytest.raises(ValueError, match="odd"):
        fit_dead_zone(bad)


def test_dead_zone_expression_matches_numeric_dead_zone():
    x = np.linspace(-3, 3, 61)
    assert np.array_equal(DeadZone().evaluate(x), dead_zone(x))
    assert np.array_equal(LinearContact().evaluate(x), x)


def test_smooth_dead_zone_error_is_half_its_width():
    # Closed form of the largest error, at x = +-1: (e + 2 - sqrt(4 + e^2)) / 2 -> e/2.
    for e in (0.1, 0.01):
        model = SmoothDeadZone(e)
        expected = (e + 2 - np.sqrt(4 + e**2)) / 2
        assert model.max_error() == pytest.approx(expected, rel=1e-3)
        xs = sp.Symbol("x", real=True)
        expr = model.expression(xs).subs(sp.Symbol("eps_g", real=True), e)
        assert sp.simplify(expr.subs(xs, -xs) + expr) == 0  # odd


def _brute_force_fit(order, fit_range, step):
    # Reference: the definition of the discrete fit, summed sample by sample in rationals.
    from fractions import Fraction

    from gearsym.derive.mesh.backlash import _solve_exact

    n = int(round(2.0 * fit_range / step)) + 1
    a, m = Fraction(fit_range), n - 1
    powers = range(1, order + 1, 2)
    ts = [Fraction(2 * i - m, m) for i in range(n)]
    dz = [a * t - 1 if a * t > 1 else a * t + 1 if a * t < -1 else 0 for t in ts]
    gram = [[sum(t ** (p + q) for t in ts) for q in powers] for p in powers]
    rhs = [sum(t**p * d for t, d in zip(ts, dz, strict=True)) for p in powers]
    return tuple(float(c / a**p) for c, p in zip(_solve_exact(gram, rhs), powers, strict=True))


@pytest.mark.parametrize("args", [(7, 3.0, 0.01), (5, 2.7, 0.013), (9, 4.0, 0.5), (1, 1.01, 0.1)])
def test_fit_is_the_exact_least_squares_solution(args):
    # The closed-form sample sums give bit for bit the correctly rounded exact solution, so
    # the generated files do not depend on the machine's BLAS kernel.
    assert fit_dead_zone(*args).coefficients == _brute_force_fit(*args)


def test_fit_agrees_with_a_floating_point_least_squares_solve():
    # Reference: numpy.linalg.lstsq on the scaled Vandermonde matrix (the former method).
    fit = fit_dead_zone(7, 3.0, 0.01)
    x = np.linspace(-3.0, 3.0, fit.samples)
    powers = np.array(fit.powers)
    scaled = np.linalg.lstsq((x[:, None] / 3.0) ** powers, dead_zone(x), rcond=None)[0]
    assert np.allclose(fit.coefficients, scaled / 3.0**powers, rtol=1e-12, atol=0)
