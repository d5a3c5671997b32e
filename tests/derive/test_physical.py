"""Physical quantities in the generated parameters() (derive/physical.py).

References:
* the derivation itself, through another route: a variant of the topology with the value
  written into its data (``with_open_values``), derived by SymPy from the start;
* the audit page's closed forms evaluated here by hand from the module's own linear data
  (``STRUCTURE``: masses, the incidence ``C A`` and the mean stiffnesses):
  ``omega_n = sqrt(k_m,1 W_11)`` with ``W = (C A) M^-1 (C A)^T``, ``omega = z_p n pi / 30 /
  omega_n`` and ``f_i = ((C A) M^-1 T)_i / (b_i omega_n^2)``.
"""

from __future__ import annotations

import importlib
import math

import numpy as np
import pytest
from gearsym.derive import derive_model, load_target, resolve_target
from gearsym.derive.input.open_values import with_open_values
from gearsym.resolve import needs_derivation

SHIPPED = [
    "reference_light",
    "reference_heavy",
    "reference_dead_zone",
    "reference_light_both_driving",
    "reference_linear",
    "diso",
    "siso",
    "tiso",
    "two_stage",
    "diso_bearings_light",
    "helical_pair_bearings",
]


def module(name):
    return importlib.import_module(f"gearsym.generated.{name}")


@pytest.mark.parametrize("name", SHIPPED)
def test_defaults_give_the_scenes_parameters(name):
    """Every quantity at its default gives the scene's own parameters (the derivation's)."""
    m = module(name)
    assert "speed_rpm" in m.PHYSICAL
    base = m.parameters()
    p = m.parameters(**{k: v[0] for k, v in m.PHYSICAL.items()})
    np.testing.assert_allclose(p, base, rtol=1e-12, atol=1e-15)


@pytest.mark.parametrize(
    "key, value",
    [
        ("te_amplitude_um_qg", 8.0),
        ("te_phase_deg", 30.0),
        ("layout_angle_deg_qg", 100.0),
        ("flywheel_inertia_kg_m2", 4.0),
        ("stiffness_harmonic_scale_pg", 0.5),
    ],
)
def test_a_value_gives_what_a_new_derivation_gives(key, value):
    m = module("reference_light")
    assert not needs_derivation(key, m)
    scene = load_target(resolve_target("reference-light"))
    variant = derive_model(with_open_values(scene, **{key: value}))
    np.testing.assert_allclose(
        m.parameters(**{key: value}), variant.defaults, rtol=1e-12, atol=1e-15
    )


def _closed_forms(m, speed_rpm, torques, attached_g=10.0):
    """omega and f of the DI-SO scenes by the audit page's closed forms (module doc)."""
    s = m.STRUCTURE
    mass = np.array(s["mass"], float)
    mass[2] += attached_g - 10.0  # gear g carries the flywheel (10 kg m^2 in the scene)
    ca = np.array(s["incidence"], float)
    w = ca @ np.diag(1.0 / mass) @ ca.T
    omega_n = math.sqrt(s["stiffness"][0] * w[0, 0])
    omega = s["reference_teeth"] * speed_rpm * math.pi / 30.0 / omega_n
    load = ca @ (np.asarray(torques, float) / mass)
    f = load / (np.array(s["scale"]) * omega_n**2)
    return omega, f


@pytest.mark.parametrize("speed_rpm", [600.0, 1500.0, 3000.0])
@pytest.mark.parametrize("torque_p", [200.0, 500.0])
def test_speed_and_torque_follow_the_closed_forms(speed_rpm, torque_p):
    m = module("reference_light")
    torques = [torque_p, -50.0, -900.0]
    values = {"speed_rpm": speed_rpm, "torque_Nm_p": torque_p}
    values |= {"torque_Nm_q": torques[1], "torque_Nm_g": torques[2]}
    p = dict(zip(m.PARAMETERS, m.parameters(**values), strict=True))
    omega, f = _closed_forms(m, speed_rpm, torques)
    assert p["omega"] == pytest.approx(omega, rel=1e-12)
    assert [p["f_u"], p["f_v"]] == pytest.approx(list(f), rel=1e-12)
    # with another flywheel: omega_n, hence omega and f, move together
    p = dict(zip(m.PARAMETERS, m.parameters(**values, flywheel_inertia_kg_m2=2.5), strict=True))
    omega, f = _closed_forms(m, speed_rpm, torques, attached_g=2.5)
    assert p["omega"] == pytest.approx(omega, rel=1e-12)
    assert [p["f_u"], p["f_v"]] == pytest.approx(list(f), rel=1e-12)


def test_the_scenes_torques_give_its_loads():
    """A scene with non-dimensional loads offers the steady torques that give them."""
    m = module("reference_light")
    torques = [m.PHYSICAL[f"torque_Nm_{g}"][0] for g in "pqg"]
    speed = m.PHYSICAL["speed_rpm"][0]
    omega, f = _closed_forms(m, speed, torques)
    p = dict(zip(m.PARAMETERS, m.parameters(), strict=True))
    assert omega == pytest.approx(p["omega"], rel=1e-12)
    assert list(f) == pytest.approx([p["f_u"], p["f_v"]], rel=1e-12)
    # steady: no power into the rigid-body rotation (g turns at half p's speed)
    assert torques[0] + torques[1] + 0.5 * torques[2] == pytest.approx(0.0, abs=1e-9)


def test_what_a_scene_states_is_held():
    """omega and the non-dimensional loads stay when an inertia changes; a speed or a
    torque switches that quantity to its physical form."""
    m = module("reference_light")
    p0 = dict(zip(m.PARAMETERS, m.parameters(), strict=True))
    p = dict(zip(m.PARAMETERS, m.parameters(flywheel_inertia_kg_m2=3.0), strict=True))
    assert (p["omega"], p["f_u"], p["f_v"]) == (p0["omega"], p0["f_u"], p0["f_v"])
    assert p["kappa_u_v"] != p0["kappa_u_v"]
    p = dict(zip(m.PARAMETERS, m.parameters(speed_rpm=2000.0), strict=True))
    assert p["omega"] == pytest.approx(p0["omega"] * 2000.0 / m.PHYSICAL["speed_rpm"][0])


@pytest.mark.parametrize(
    "values, words",
    [
        ({"omega": 0.6, "speed_rpm": 1000.0}, "speed_rpm and omega both set"),
        ({"lambda": 0.5, "torque_Nm_q": -10.0}, "torque_Nm_q and lambda both set"),
        ({"speed_rpm": 0.0}, "speed_rpm must be in (0, 1e+06] rpm, got 0"),
        ({"half_backlash_um": float("nan")}, "half_backlash_um must be in"),
    ],
)
def test_conflicts_and_bad_values_are_refused(values, words):
    with pytest.raises(ValueError, match=None) as err:
        module("reference_light").parameters(**values)
    assert words in str(err.value)


def test_a_sweep_and_a_map_over_physical_values_derive_nothing(monkeypatch, tmp_path):
    """`gearsym sweep --param speed_rpm` and `map --x speed_rpm --y torque_Nm_p` on a
    shipped scene run on its generated module: deriving anything fails the test."""
    import gearsym.derive as derive_package
    from gearsym.cli import main

    def refuse(*_a, **_k):
        raise AssertionError("derived a model")

    monkeypatch.setattr(derive_package, "derive_model", refuse)
    short = ["--transient", "20", "--periods", "20", "--budget", "40"]
    args = ["sweep", "reference-light", "--param", "speed_rpm", "--range", "900:1200:3"]
    assert main([*args, "--independent", "--quiet", "--out", str(tmp_path / "s"), *short]) == 0
    args = ["map", "reference-light", "--x", "speed_rpm=900:1200:2"]
    args += ["--y", "torque_Nm_p=300:500:2"]
    short += ["--lyapunov-periods", "20", "--initial-states", "1"]
    assert main([*args, "--out", str(tmp_path / "m"), *short]) == 0


def test_scales_follow_the_values():
    m = module("reference_light")
    s = m.scales(half_backlash_um=60.0, speed_rpm=1500.0)
    assert s["half_backlash_m_u"] == pytest.approx(60e-6)
    assert s["speed_rpm"] == pytest.approx(1500.0, rel=1e-12)
    assert s["omega_n_rad_per_s"] == pytest.approx(m.OMEGA_N, rel=1e-12)
