"""Helical geometry against the reference study's Table 1 and closed forms."""

import math

import pytest
from gearsym.derive.geometry import gear_geometry, pair_geometry


def study_pair(shift=(0.0, 0.0)):
    deg = math.radians
    p = gear_geometry(50, 4e-3, deg(20), deg(10), shift[0])
    g = gear_geometry(100, 4e-3, deg(20), deg(10), shift[1])
    return pair_geometry(p, g, 50e-3)


def test_contact_ratios_match_the_study_table():
    # Reference: the study's Table 1 -- 1.76 / 0.69 / 2.45.
    pair = study_pair()
    assert pair.transverse_contact_ratio == pytest.approx(1.76, abs=0.005)
    assert pair.axial_contact_ratio == pytest.approx(0.69, abs=0.005)
    assert pair.total_contact_ratio == pytest.approx(2.45, abs=0.005)


def test_base_radius_and_base_helix_closed_forms():
    # r_b = z mn cos(alpha_t) / (2 cos beta); tan(beta_b) = tan(beta) cos(alpha_t).
    g = gear_geometry(50, 4e-3, math.radians(20), math.radians(10))
    alpha_t = math.atan(math.tan(math.radians(20)) / math.cos(math.radians(10)))
    assert g.base_radius == pytest.approx(
        50 * 4e-3 * math.cos(alpha_t) / (2 * math.cos(math.radians(10))), rel=1e-14
    )
    assert math.tan(g.base_helix_angle) == pytest.approx(
        math.tan(math.radians(10)) * math.cos(alpha_t), rel=1e-14
    )


def test_zero_sum_shift_keeps_the_reference_centre_distance():
    # x1 + x2 = 0: working pressure angle = transverse pressure angle (ISO 21771).
    pair = study_pair((0.3, -0.3))
    assert pair.working_pressure_angle == pair.driver.transverse_pressure_angle
    assert pair.centre_distance == pytest.approx(
        pair.driver.pitch_radius + pair.driven.pitch_radius, rel=1e-14
    )


def test_positive_shift_sum_spreads_the_centres():
    base, shifted = study_pair(), study_pair((0.2, 0.2))
    assert shifted.centre_distance > base.centre_distance
    assert shifted.working_pressure_angle > base.working_pressure_angle
