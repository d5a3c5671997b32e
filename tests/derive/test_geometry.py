"""Helical geometry against the reference study's Table 1 and closed forms (ISO 21771)."""

import math
import tomllib

import pytest
from gearsym.derive.input.topology import parse_topology
from gearsym.derive.mesh.geometry import (
    CentreDistanceError,
    backlash_free_shift_sum,
    gear_geometry,
    pair_geometry,
    with_tip_radius,
)
from gearsym.derive.mesh.stiffness import contact_line_stiffness


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


def test_given_centre_distance_inverts_the_profile_shift_sum():
    # ISO 21771: inv(alpha_wt) = inv(alpha_t) + 2 tan(alpha_n) (x1 + x2) / (z1 + z2) and
    # cos(alpha_wt) = a cos(alpha_t) / a_w are one relation read both ways: the centre
    # distance the shifts give, given back, returns the same pair and the same shift sum.
    from_shifts = study_pair((0.3, 0.2))
    p, g = from_shifts.driver, from_shifts.driven
    given = pair_geometry(p, g, 50e-3, from_shifts.centre_distance)
    assert given.working_pressure_angle == pytest.approx(
        from_shifts.working_pressure_angle, rel=1e-12
    )
    assert given.transverse_contact_ratio == pytest.approx(
        from_shifts.transverse_contact_ratio, rel=1e-12
    )
    assert backlash_free_shift_sum(p, g, from_shifts.centre_distance) == pytest.approx(
        0.5, abs=1e-12
    )


def test_a_wider_centre_distance_opens_the_pressure_angle_and_shortens_contact():
    # a_w sin(alpha_wt) = sqrt(a_w^2 - (r_b1 + r_b2)^2): the line of action grows with a_w
    # while the tips stay put, so the path of contact shrinks by exactly that growth.
    ref = study_pair()
    a_w = ref.centre_distance + 1e-3
    wide = pair_geometry(ref.driver, ref.driven, 50e-3, a_w)
    bases = ref.driver.base_radius + ref.driven.base_radius
    assert math.cos(wide.working_pressure_angle) == pytest.approx(bases / a_w, rel=1e-14)
    growth = math.sqrt(a_w**2 - bases**2) - ref.line_of_action
    assert ref.path_of_contact - wide.path_of_contact == pytest.approx(growth, rel=1e-9)


def test_a_centre_distance_closer_than_the_shifts_allow_is_refused():
    # x1 + x2 = 0.5 needs the centre distance of study_pair((0.3, 0.2)); 10 um closer the
    # teeth would jam (negative backlash).
    shifted = study_pair((0.3, 0.2))
    with pytest.raises(CentreDistanceError, match="the teeth would jam"):
        pair_geometry(shifted.driver, shifted.driven, 50e-3, shifted.centre_distance - 1e-5)


def test_given_tip_sets_every_tip_quantity():
    # The standard tip given back changes nothing; a tip shortened by 0.1 mn shortens the
    # path of contact by sqrt(ra^2 - rb^2) - sqrt(ra'^2 - rb^2) (ISO 21771) and raises the
    # tip thickness 2 r_a (base_half_angle - inv(alpha_a)).
    ref = study_pair()
    p, g = ref.driver, ref.driven
    same = pair_geometry(with_tip_radius(p, p.tip_radius), g, 50e-3)
    assert same == ref
    short = with_tip_radius(p, p.tip_radius - 0.4e-3)
    pair = pair_geometry(short, g, 50e-3)
    loss = math.sqrt(p.tip_radius**2 - p.base_radius**2) - math.sqrt(
        short.tip_radius**2 - p.base_radius**2
    )
    assert ref.path_of_contact - pair.path_of_contact == pytest.approx(loss, rel=1e-12)
    assert pair.active_radii[0][1] == short.tip_radius
    assert short.tip_thickness > p.tip_thickness


def test_the_pointed_tip_diameter_the_message_names_is_where_the_tooth_ends():
    # inv(alpha_a) = base_half_angle at the pointed tip: 8 teeth with x = 1.5 (the pointed
    # case of test_input_errors) end at d_a = 47.897 mm; just below it the tip is sharp.
    g = gear_geometry(8, 4e-3, math.radians(20), 0.0, 1.5)
    with pytest.raises(ValueError, match="give a tip diameter below 47.897 mm"):
        with_tip_radius(g, 0.050 / 2)
    assert with_tip_radius(g, 0.047896 / 2).tip_thickness == pytest.approx(0.0, abs=1e-5)


def test_topology_keys_reach_the_pair(root):
    # tip_diameter_mm and centre_distance_mm give the same pair as the geometry functions,
    # and the stiffness (here from the contact-line length) is computed on that pair.
    text = (root / "scenes" / "topologies" / "siso.toml").read_text()
    text = text.replace('id = "p"\n', 'id = "p"\ntip_diameter_mm = 210.8\n', 1)
    text = text.replace('coordinate = "u"\n', 'coordinate = "u"\ncentre_distance_mm = 304.9\n')
    text = text.replace(
        '{ source = "potential-energy", slices = 200, harmonics = 10 }',
        '{ source = "contact-line", mean_N_per_m = 1.0e9, harmonics = 4 }',
    )
    mesh = parse_topology(tomllib.loads(text), "siso-drawn").meshes[0]
    ref = study_pair()
    tipped = with_tip_radius(ref.driver, 210.8 * 0.5e-3)  # mm to m as the loader does
    expected = pair_geometry(tipped, ref.driven, 50e-3, 304.9 * 1e-3)
    assert mesh.pair == expected
    assert mesh.stiffness == contact_line_stiffness(
        1.0e9, expected.transverse_contact_ratio, expected.axial_contact_ratio, 4
    )
