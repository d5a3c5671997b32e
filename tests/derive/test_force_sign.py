"""Where each backlash model's force is zero, its sign elsewhere, and the polynomial's
static equilibria.

References: ``numpy.roots`` of the study's polynomial (an eigenvalue solve of the companion
matrix, independent of the exact root isolation under test); the dead zone's definition;
a direct evaluation of g on a fine grid; the saddle-node of ``g(x) = F`` (``g' = 0``).
"""

import numpy as np
import pytest
from gearsym.derive import derive_model, load_target, resolve_target
from gearsym.derive.mesh.backlash import (
    DeadZone,
    ForceSign,
    LinearContact,
    SmoothDeadZone,
    fit_dead_zone,
)

STUDY = fit_dead_zone()  # 0.0017 x^7 - 0.0366 x^5 + 0.2833 x^3 - 0.1555 x


def _numpy_coefficients(fit, load=0.0):
    """Highest power first, as numpy.roots wants, minus ``load``."""
    c = np.zeros(fit.order + 1)
    for k, a in zip(fit.powers, fit.coefficients, strict=True):
        c[fit.order - k] = a
    c[-1] -= load
    return c


def _real(roots):
    return np.sort(roots[np.abs(roots.imag) < 1e-9].real)


def test_study_polynomial_zeros_match_numpy_roots():
    # Reference: numpy.roots of the study's coefficients (7 roots; 3 real: 0, +-0.7701).
    sign = STUDY.force_sign()
    expected = _real(np.roots(_numpy_coefficients(STUDY)))
    assert expected.size == 3
    np.testing.assert_allclose(sign.zeros, expected, rtol=0, atol=1e-12)
    assert sign.zeros[1] == 0.0 and sign.zeros[0] == -sign.zeros[2]
    assert round(sign.zeros[2], 3) == 0.770  # the issue's +-0.770, not the dead zone's +-1


def test_study_polynomial_signs_match_a_direct_evaluation():
    # Reference: g evaluated on a grid of [-3, 3] (the fit's valid range).
    sign = STUDY.force_sign()
    assert sign.signs == (-1, 1, -1, 1)
    x = np.linspace(-3, 3, 6001)
    g = STUDY.evaluate(x)
    bounds = (-np.inf, *sign.zeros, np.inf)
    for s, a, b in zip(sign.signs, bounds[:-1], bounds[1:], strict=True):
        inside = (x > a + 1e-9) & (x < b - 1e-9)
        assert np.all(np.sign(g[inside]) == s)
    assert sign.edges == (sign.zeros[0], sign.zeros[2])
    assert sign.zero_between is False and sign.loaded_in_gap is True


@pytest.mark.parametrize(
    ("model", "zeros", "signs", "between", "loaded"),
    [
        (DeadZone(), (-1.0, 1.0), (-1, 0, 1), True, False),  # zero on [-1, 1]
        (LinearContact(), (0.0,), (-1, 1), False, True),  # g = x
        (SmoothDeadZone(0.05), (0.0,), (-1, 1), False, True),  # strictly increasing
    ],
)
def test_closed_form_models_state_their_sign(model, zeros, signs, between, loaded):
    sign = model.force_sign()
    assert (sign.zeros, sign.signs) == (zeros, signs)
    assert sign.zero_between is between and sign.loaded_in_gap is loaded
    x = np.linspace(-3, 3, 6001)
    s = np.sign(model.evaluate(x))
    bounds = (-np.inf, *zeros, np.inf)
    for v, a, b in zip(signs, bounds[:-1], bounds[1:], strict=True):
        assert np.all(s[(x > a) & (x < b)] == v)


def test_force_sign_refuses_an_inconsistent_table():
    with pytest.raises(ValueError, match="sorted"):
        ForceSign((1.0, -1.0), (-1, 0, 1))
    with pytest.raises(ValueError, match="one sign"):
        ForceSign((0.0,), (-1, 0, 1))


@pytest.mark.parametrize("load", [0.0, 0.01, -0.0123, 0.03, 0.044, 0.1, 0.5, -0.5])
def test_equilibria_are_the_real_roots_of_g_minus_load(load):
    # Reference: numpy.roots of g(x) - F; stability from g' by numpy.polyder.
    eq = STUDY.equilibria(load)
    c = _numpy_coefficients(STUDY, load)
    expected = _real(np.roots(c))
    expected = expected[np.abs(expected) <= 3.0]
    np.testing.assert_allclose([e.x for e in eq], expected, rtol=0, atol=1e-9)
    slopes = np.polyval(np.polyder(c), expected)
    np.testing.assert_allclose([e.slope for e in eq], slopes, rtol=1e-9, atol=1e-12)
    assert [e.stable for e in eq] == list(slopes > 0)
    assert [e.spurious for e in eq] == list((slopes > 0) & (expected * load < 0))


def test_spurious_equilibrium_exists_below_the_saddle_node_load():
    # Reference: F* = g at the root of g' in (-0.7701, 0) (numpy.roots of g').
    limit = STUDY.spurious_load_limit()
    c = _numpy_coefficients(STUDY)
    crit = _real(np.roots(np.polyder(c)))
    x_star = crit[(crit < 0) & (crit > -0.7702)]
    assert x_star.size == 1
    assert limit == pytest.approx(np.polyval(c, x_star[0]), rel=1e-12)
    assert 0.0448 < limit < 0.0449
    for load in (0.01, 0.5 * limit, 0.999 * limit, -0.999 * limit):
        spurious = [e for e in STUDY.equilibria(load) if e.spurious]
        assert len(spurious) == 1 and spurious[0].in_gap
    for load in (1.001 * limit, 0.1, -0.1):
        assert not any(e.spurious for e in STUDY.equilibria(load))
    assert DeadZone().force_sign().zero_between  # the dead zone has no such well


def test_shipped_contracts_carry_the_force_sign_of_their_backlash():
    # Reference: the scenes' backlash models (reference-light: the study's fit;
    # reference-dead-zone: the dead zone), both meshes alike.
    light = derive_model(load_target(resolve_target("reference-light"))).contract
    dead = derive_model(load_target(resolve_target("reference-dead-zone"))).contract
    z = STUDY.force_sign().zeros
    for q in ("u", "v"):
        assert light["force_sign"][q] == {
            "edges": (z[0], z[2]),
            "zero_between": False,
            "zeros": z,
            "signs": (-1, 1, -1, 1),
        }
        assert dead["force_sign"][q] == {
            "edges": (-1.0, 1.0),
            "zero_between": True,
            "zeros": (-1.0, 1.0),
            "signs": (-1, 0, 1),
        }
        assert light["contact"][q] == dead["contact"][q] == (-1.0, 1.0)  # the gap
