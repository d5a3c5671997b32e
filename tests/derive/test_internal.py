"""Internal gears (rings) in a torsional model, against closed forms worked by hand here.

References, each computed in this file from the formulas, not by the code under test:

* centre distance and working pressure angle of an internal pair: ISO 21771 (and SDP/SI,
  Elements of Metric Gear Technology, section 5): ``a = (d2 - d1)/2`` at zero shift,
  ``inv(alpha_wt) = inv(alpha_t) + 2 tan(alpha_n) (x2 - x1)/(z2 - z1)``,
  ``a_w = a cos(alpha_t)/cos(alpha_wt)``;
* transverse contact ratio of an internal pair:
  ``(sqrt(ra1^2 - rb1^2) - sqrt(ra2^2 - rb2^2) + a_w sin(alpha_wt)) / (pi m cos(alpha_t))``;
* ISO 6336-1 method B: ``q' = C1 + C2/z_n1`` for a zero-shift pinion meshing a ring
  (``z_n2 = infinity``), ``c_gamma_alpha = c' (0.75 eps_alpha + 0.25)``,
  ``c' = 0.8 C_B / q'``, ``C_B = 1 + 0.5 (1.2 - 1.25)``;
* the torsional two-inertia oscillator: ``omega^2 = k_m (r_b1^2/I_1 + r_b2^2/I_2)`` (spur,
  one mesh), with the rigid-body mode at zero;
* the static mesh force of a balanced pair: ``F = T_1 / r_b1``, positive (the pinion's
  working flanks loaded) for a driving pinion torque.
"""

import json
import math
from fractions import Fraction

import pytest
from gearsym.cli import main
from gearsym.derive import derive_model, load_target
from gearsym.derive.build import describe
from gearsym.derive.input.topology import load_topology
from gearsym.derive.mesh.geometry import gear_geometry
from gearsym.derive.mesh.internal import internal_pair, ring_geometry

ALPHA = math.radians(20.0)
M = 3e-3


def inv(a):
    return math.tan(a) - a


def inv_inverse(value):
    lo, hi = 1e-6, 1.4
    for _ in range(200):  # bisection: inv is increasing on (0, pi/2)
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if inv(mid) < value else (lo, mid)
    return 0.5 * (lo + hi)


@pytest.fixture(scope="module")
def topo(root):
    return load_topology(root / "scenes" / "topologies" / "ring-pinion.toml")


@pytest.fixture(scope="module")
def model(root):
    return derive_model(load_target(root / "scenes" / "topologies" / "ring-pinion.toml"))


def test_ring_tip_is_inside_its_reference_circle_and_root_outside():
    ring = ring_geometry(80, M, ALPHA, 0.0)
    assert ring.pitch_radius == pytest.approx(0.120)
    assert ring.tip_radius == pytest.approx(0.120 - M)  # d_a = d - 2 m (x = 0)
    assert ring.root_radius == pytest.approx(0.120 + 1.25 * M)
    assert ring.tip_radius < ring.pitch_radius < ring.root_radius


def test_centre_distance_and_contact_ratio_of_the_shipped_pair(topo):
    pair = topo.meshes[0].pair
    assert pair.internal
    a = (240e-3 - 60e-3) / 2  # (d2 - d1)/2
    rb1, rb2 = 30e-3 * math.cos(ALPHA), 120e-3 * math.cos(ALPHA)
    ra1, ra2 = 33e-3, 235e-3 / 2  # pinion d + 2 m; ring tip as drawn
    g = math.sqrt(ra1**2 - rb1**2) - math.sqrt(ra2**2 - rb2**2) + a * math.sin(ALPHA)
    eps = g / (math.pi * M * math.cos(ALPHA))
    assert pair.centre_distance == pytest.approx(a, rel=1e-12)
    assert pair.working_pressure_angle == pytest.approx(ALPHA, rel=1e-12)
    assert pair.transverse_contact_ratio == pytest.approx(eps, rel=1e-12)
    assert 1.6 < eps < 1.8  # between one and two pairs: the rectangular wave


def test_working_pressure_angle_and_centre_distance_with_shifts():
    x1, x2 = 0.1, 0.4
    pair = internal_pair(
        gear_geometry(20, M, ALPHA, 0.0, x1), ring_geometry(80, M, ALPHA, 0.0, x2), 0.03
    )
    alpha_w = inv_inverse(inv(ALPHA) + 2 * math.tan(ALPHA) * (x2 - x1) / (80 - 20))
    assert pair.working_pressure_angle == pytest.approx(alpha_w, rel=1e-10)
    assert pair.centre_distance == pytest.approx(
        0.090 * math.cos(ALPHA) / math.cos(alpha_w), rel=1e-10
    )
    assert pair.centre_distance > 0.090  # x2 - x1 > 0 moves the pinion outwards


def test_pinion_and_ring_turn_the_same_way(topo, root):
    assert topo.signed_speed_ratios("p")["r"] == Fraction(20, 80)
    assert topo.senses()["p"] == topo.senses()["r"]
    external = load_topology(root / "scenes" / "topologies" / "siso.toml")
    assert external.signed_speed_ratios("p")["g"] == Fraction(-50, 100)


def hand_stiffness(eps):
    q = 0.04723 + 0.15551 / 20  # ISO 6336-1 method B, x = 0, z_n2 = infinity
    c_prime = 0.8 * (1 + 0.5 * (1.2 - 1.25)) / q
    return c_prime * (0.75 * eps + 0.25) * 30 * 1e6  # N/(mm um) x b (mm) -> N/m


def hand_inertias():
    rho, b = 7850.0, 0.030
    pinion = 0.5 * rho * math.pi * b * (0.030**4 - 0.010**4)  # blank, bore 10 mm
    return pinion, 0.0605 + 0.5  # ring: given rim plus attached


def test_mean_stiffness_is_iso_6336_method_b_with_the_ring_as_a_rack(topo):
    mesh = topo.meshes[0]
    assert mesh.stiffness.source == "iso-6336"
    eps = mesh.pair.transverse_contact_ratio
    assert mesh.stiffness.mean == pytest.approx(hand_stiffness(eps), rel=1e-8)


def test_natural_frequency_is_the_two_inertia_closed_form(model, topo):
    i1, i2 = hand_inertias()
    rb1, rb2 = 30e-3 * math.cos(ALPHA), 120e-3 * math.cos(ALPHA)
    k = hand_stiffness(topo.meshes[0].pair.transverse_contact_ratio)
    omega = math.sqrt(k * (rb1**2 / i1 + rb2**2 / i2))
    assert model.scales["omega_n_rad_per_s"] == pytest.approx(omega, rel=1e-7)


def test_static_mesh_force_is_pinion_torque_over_base_radius(model, topo):
    f = describe(model)["f"]["u"]
    mesh = topo.meshes[0]
    omega_n = model.scales["omega_n_rad_per_s"]
    i1, i2 = hand_inertias()
    rb1, rb2 = 30e-3 * math.cos(ALPHA), 120e-3 * math.cos(ALPHA)
    # f = F / (b k_m) at the mean stiffness, with k_m W = omega_n^2.
    force = f * mesh.half_backlash * omega_n**2 / (rb1**2 / i1 + rb2**2 / i2)
    assert force == pytest.approx(100.0 / rb1, rel=1e-9)
    assert force > 0


def test_audit_page_states_the_sign_the_force_and_the_method(model):
    from gearsym.derive.emit.audit import audit_page

    page = audit_page(model, "gearsym derive")
    assert "### Internal meshes" in page
    assert "+1/4" in page
    assert "iso-6336" in page and "external teeth" in page
    assert r"\varphi_{r}" in page  # the one-frame deflection, a difference


def test_modes_and_simulate_run_on_the_shipped_pair(capsys, topo):
    code = main(["modes", "ring-pinion", "--json"])
    out = capsys.readouterr()
    assert code == 0, out.err
    freqs = [m["frequency_hz"] for m in json.loads(out.out)["modes"]]
    i1, i2 = hand_inertias()
    rb1, rb2 = 30e-3 * math.cos(ALPHA), 120e-3 * math.cos(ALPHA)
    k = hand_stiffness(topo.meshes[0].pair.transverse_contact_ratio)
    hz = math.sqrt(k * (rb1**2 / i1 + rb2**2 / i2)) / (2 * math.pi)
    assert max(freqs) == pytest.approx(hz, rel=1e-6)
    quick = ["--transient", "10", "--periods", "20", "--lyapunov-periods", "0"]
    assert main(["simulate", "ring-pinion", *quick]) == 0, capsys.readouterr().err


REFUSALS = [
    # (what, old text, new text, expected fragment)
    (
        "ring with fewer teeth than the pinion",
        "teeth = 20\n",
        "teeth = 90\n",
        "a ring needs more teeth than its pinion",
    ),
    (
        "ring meshing a ring",
        'id = "p"\n',
        'id = "p"\ninternal = true\ninertia_kg_m2 = 1.0\n',
        "two rings (internal gears) cannot mesh",
    ),
    (
        "potential-energy method on an internal pair",
        'source = "iso-6336"',
        'source = "potential-energy"',
        'for external teeth; for a pinion and ring use "iso-6336"',
    ),
    (
        "centre distance below the difference of the base radii",
        'driven = "r"\n',
        'driven = "r"\ncentre_distance_mm = 80\n',
        "not above the difference of the base radii",
    ),
    (
        "ring on a bearing",
        "[operating]",
        '[[bearing]]\ngear = "r"\nradial_N_per_m = 1e9\naxial_N_per_m = 1e9\n\n[operating]',
        "internal gears are supported in torsional models",
    ),
]


@pytest.mark.parametrize("what, old, new, expected", REFUSALS, ids=[c[0] for c in REFUSALS])
def test_refusals_are_one_line_with_exit_code_2(tmp_path, root, capsys, what, old, new, expected):
    text = (root / "scenes" / "topologies" / "ring-pinion.toml").read_text()
    if what == "ring meshing a ring":  # a ring of 40 teeth has an involute to mesh on
        text = text.replace("bore_radius_mm = 10\n", "").replace("teeth = 20\n", "teeth = 40\n")
    assert old in text
    path = tmp_path / "bad.toml"
    path.write_text(text.replace(old, new, 1))
    code = main(["derive", str(path), "--dry-run"])
    err = capsys.readouterr().err
    assert code == 2, err
    assert err.count("\n") == 1 and "Traceback" not in err, err
    assert expected in err, err


def test_trochoid_interference_against_the_published_tooth_difference():
    """SDP/SI (section 5, after eq. 5-8): a pinion meshing a standard 20 deg internal gear
    is free of trochoid interference when z2 - z1 > 9; a difference of a few teeth is not."""
    from gearsym.derive.mesh.internal import _trochoid_margin

    for z1 in (20, 30, 40, 60):
        ring = ring_geometry(max(z1 + 10, 40), M, ALPHA, 0.0)
        pair = internal_pair(gear_geometry(z1, M, ALPHA, 0.0), ring, 0.03)
        assert _trochoid_margin(pair) > 0.0, z1
        if z1 + 4 < 34:  # a ring needs 34 teeth for its tip to clear its base circle
            continue
        close = internal_pair(
            gear_geometry(z1, M, ALPHA, 0.0), ring_geometry(z1 + 4, M, ALPHA, 0.0), 0.03
        )
        assert _trochoid_margin(close) < 0.0, z1


def test_stiffness_report_refuses_an_internal_mesh_in_one_line(capsys):
    code = main(["stiffness", "ring-pinion"])
    err = capsys.readouterr().err
    assert code == 2, err
    assert err.count("\n") == 1 and "Traceback" not in err, err
    assert "external teeth only" in err, err
