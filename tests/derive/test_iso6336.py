"""ISO 6336-1 method B stiffness against the standard's worked example."""

import math

import pytest
from gearsym.derive.mesh.geometry import gear_geometry, pair_geometry, with_tip_radius
from gearsym.derive.mesh.iso6336 import iso_stiffness

deg = math.radians


def tr_example_1(tip_diameters=None, centre_distance=None):
    """ISO/TR 6336-30:2017, "Calculation examples for the application of ISO 6336 parts 1, 2,
    3, 5", example 1: z = 17/103, m_n = 8 mm, alpha_n = 20 deg, beta = 15.8 deg,
    b = 100 mm, x = 0.145/0, basic rack h_fP = 1.4 m_n, rho_fP = 0.39 m_n, a = 500 mm,
    solid discs.  Without ``tip_diameters`` (m) the tips are r + (1 + x) m_n, without
    ``centre_distance`` (m) it follows from the profile shifts."""
    p = gear_geometry(
        17, 8e-3, deg(20), deg(15.8), 0.145, dedendum_coefficient=1.4, root_radius_coefficient=0.39
    )
    g = gear_geometry(
        103, 8e-3, deg(20), deg(15.8), 0.0, dedendum_coefficient=1.4, root_radius_coefficient=0.39
    )
    if tip_diameters is not None:
        p, g = (with_tip_radius(gear, d / 2) for gear, d in zip((p, g), tip_diameters, strict=True))
    return pair_geometry(p, g, 0.1, centre_distance)


def test_worked_example_of_the_technical_report():
    # Reference values: ISO/TR 6336-30:2017 example 1 as printed (z_n 18.905 / 114.543,
    # c'_th 17.85584, c' 12.37047, c_gamma_alpha 17.46485, c_gamma_beta 14.84512 N/(mm um)).
    pair = tr_example_1()
    assert pair.centre_distance == pytest.approx(0.5, abs=1e-5)  # the example's a = 500 mm
    iso = iso_stiffness(pair)
    assert iso.virtual_teeth[0] == pytest.approx(18.905, abs=5e-4)
    assert iso.virtual_teeth[1] == pytest.approx(114.543, abs=5e-4)
    assert iso.c_th == pytest.approx(17.85584, abs=5e-6)
    assert iso.c_b == pytest.approx(0.9, abs=1e-12)  # h_fP = 1.4 m_n
    assert iso.c_prime == pytest.approx(12.37047, abs=5e-6)
    # c_gamma = c' (0.75 eps_alpha + 0.25): the report's eps_alpha (1.5491, implied by its
    # c_gamma_alpha / c') comes from its rounded tip diameters and a = 500 mm; ours from
    # r + (1 + x) m_n and the shifts' a_w = 499.998 mm is 1.5495, which moves c_gamma by
    # 2.4e-4 relative (test_worked_example_with_the_drawn_tips_and_centre_distance gives
    # the drawing's values instead).
    assert pair.transverse_contact_ratio == pytest.approx(1.5491, abs=1e-3)
    assert iso.c_gamma_alpha == pytest.approx(17.46485, rel=5e-4)
    assert iso.c_gamma_beta == pytest.approx(14.84512, rel=5e-4)
    assert iso.c_gamma_beta == pytest.approx(0.85 * iso.c_gamma_alpha, rel=1e-15)


def test_worked_example_with_the_drawn_tips_and_centre_distance():
    # Reference: ISO/TR 6336-30:2017 example 1, c_gamma_alpha = 17.46485 and
    # c_gamma_beta = 14.84512 N/(mm um) as printed, at its centre distance a = 500 mm.
    # Tip diameters 159.66 / 872.35 mm: d + 2 (1 + x) m_n (159.6601 / 872.3548 mm) to
    # 0.01 mm -- not read from the report's table, but the only pair on that 0.01 mm grid
    # that reproduces its printed c_gamma_alpha (every neighbour is >= 8e-5 off).  With them
    # eps_alpha = 1.54909 (what the print implies) and c_gamma_alpha is 2e-8 relative off
    # the print, so the test holds it to half a unit in the last printed digit (5e-6, i.e.
    # 3e-7 relative; it was 5e-4 relative with the standard tips and the shifts' centre
    # distance, 2.4e-4 off: the test above).
    pair = tr_example_1((159.66e-3, 872.35e-3), 0.5)
    assert pair.centre_distance == 0.5
    assert pair.transverse_contact_ratio == pytest.approx(1.54909, abs=5e-6)
    iso = iso_stiffness(pair)
    assert iso.c_gamma_alpha == pytest.approx(17.46485, abs=5e-6)
    assert iso.c_gamma_beta == pytest.approx(14.84512, abs=5e-6)


def test_coefficients_and_factors_of_method_b():
    # ISO 6336-1:2019 method B: C_B of the standard rack = 0.975, the low line-load
    # reduction (F_t K_A / b / 100)^0.25 and the blank factor C_R.
    p = gear_geometry(50, 4e-3, deg(20), deg(10))
    g = gear_geometry(100, 4e-3, deg(20), deg(10))
    pair = pair_geometry(p, g, 0.05)
    full = iso_stiffness(pair)
    assert full.c_b == pytest.approx(0.975, abs=1e-12)
    low = iso_stiffness(pair, line_load=50.0)
    assert low.c_prime / full.c_prime == pytest.approx(0.5**0.25, rel=1e-14)
    webbed = iso_stiffness(pair, blank=((0.5, 8e-3), (0.5, 8e-3)))
    expected = 1 + math.log(0.5) / (5 * math.exp(2.0 / 5))
    assert webbed.c_r == pytest.approx(expected, rel=1e-14)
    assert full.mesh_stiffness == pytest.approx(full.c_gamma_alpha * 50 * 1e6, rel=1e-14)
