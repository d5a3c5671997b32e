"""Open values (derive/input/open_values.py): each carried through the derivation consistently.

References: closed forms of the reduced torsional model -- the coupling between two meshes
on one gear goes through that gear's inertia alone, so kappa_uv omega_n^2 I_g is the same
for every flywheel; E = transmission-error amplitude / half backlash; the layout phase
2 pi delta with delta the fractional number of teeth spanned (the study's definition).
"""

import math

import numpy as np
import pytest
from gearsym.derive import InputError, derive_model, load_target, resolve_target
from gearsym.derive.input.open_values import is_open_value, with_open_values


@pytest.fixture(scope="module")
def scene():
    return load_target(resolve_target("reference-light"))


def _model(scene, **values):
    model = derive_model(with_open_values(scene, **values))
    return model, dict(zip(model.parameter_names, model.defaults, strict=True))


def test_flywheel_changes_the_couplings_together_as_the_closed_form_says(scene):
    rows = []
    for J in (2.0, 10.0, 40.0):
        variant = with_open_values(scene, flywheel_inertia_kg_m2=J)
        gear = variant.topology.gear("g")
        assert gear.inertia == pytest.approx(gear.gear_inertia + J)
        model, p = _model(scene, flywheel_inertia_kg_m2=J)
        wn = model.scales["omega_n_rad_per_s"]
        # the coupling goes through gear g alone: kappa_uv omega_n^2 I_g does not depend
        # on I_g; with each mesh's damping on its own mass (c_v = 2 zeta sqrt(k_v / W_vv))
        # and equal meshes, xi_uv = zeta W_uv / W_vv = zeta kappa_uv
        zeta = scene.parameters["damping_ratio"]
        assert p["xi_u_v"] == pytest.approx(zeta * p["kappa_u_v"], rel=1e-9)
        assert p["xi_v_u"] == pytest.approx(zeta * p["kappa_v_u"], rel=1e-9)
        rows.append(
            (p, p["kappa_u_v"] * wn**2 * gear.inertia, p["kappa_v_u"] * wn**2 * gear.inertia)
        )
    for row in rows[1:]:
        assert row[1:] == pytest.approx(rows[0][1:], rel=1e-9)
    # a heavier flywheel weakens every coupling term
    kuv = [r[0]["kappa_u_v"] for r in rows]
    xuv = [r[0]["xi_u_v"] for r in rows]
    assert kuv[0] > kuv[1] > kuv[2] and xuv[0] > xuv[1] > xuv[2]


def test_transmission_error_amplitude_becomes_e_over_the_half_backlash(scene):
    _, p = _model(scene, te_amplitude_um=12.5)
    half_backlash_um = 50.0  # scenes/topologies/diso.toml
    assert p["E_u_1"] == pytest.approx(12.5 / half_backlash_um, rel=1e-12)
    assert p["E_v_1"] == pytest.approx(12.5 / half_backlash_um, rel=1e-12)
    _, p = _model(scene, te_amplitude_um_qg=2.5, te_phase_deg_qg=30.0)
    assert p["E_u_1"] == pytest.approx(5.0 / half_backlash_um)  # the scene's own 5 um
    assert p["E_v_1"] == pytest.approx(2.5 / half_backlash_um)
    assert p["psi_v_1"] == pytest.approx(math.radians(30.0))


@pytest.mark.parametrize("angle", [90.0, 100.0, 120.0])
def test_layout_angle_gives_the_study_phase(scene, angle):
    _, p = _model(scene, layout_angle_deg=angle)
    spanned = 100 * angle / 360.0  # teeth of g between the two pinions
    delta = spanned - math.floor(spanned)
    expected = 2 * math.pi * delta
    got = p["phi_v"] % (2 * math.pi)
    assert min(abs(got - expected), 2 * math.pi - abs(got - expected)) < 1e-9


def test_stiffness_harmonic_scale_scales_every_harmonic_and_keeps_the_mean(scene):
    _, ref = _model(scene)
    _, p = _model(scene, stiffness_harmonic_scale=0.5)
    for key in ref:
        if key.startswith(("kc_", "ks_")):
            assert p[key] == pytest.approx(0.5 * ref[key], rel=1e-12, abs=1e-15)
    assert p["kappa_u_u"] == ref["kappa_u_u"] and p["kappa_u_v"] == ref["kappa_u_v"]


def test_the_scene_open_table_equals_the_keyword(tmp_path, root):
    text = (root / "scenes" / "reference-light.toml").read_text()
    topo = (root / "scenes" / "topologies" / "diso.toml").as_posix()
    text = text.replace('topology = "topologies/diso.toml"', f'topology = "{topo}"')
    path = tmp_path / "open.toml"
    assert "\n[open]\n" in text
    extra = "te_amplitude_um = 8.0\nflywheel_inertia_kg_m2 = 3.0\n"
    path.write_text(text.replace("\n[open]\n", "\n[open]\n" + extra))
    from_file = derive_model(load_target(path))
    scene = load_target(resolve_target("reference-light"))
    keyword = derive_model(with_open_values(scene, te_amplitude_um=8.0, flywheel_inertia_kg_m2=3.0))
    assert np.allclose(from_file.defaults, keyword.defaults, rtol=1e-12)


def test_open_value_names():
    assert is_open_value("te_amplitude_um") and is_open_value("te_amplitude_um_qg")
    assert is_open_value("flywheel_inertia_kg_m2") and is_open_value("attached_inertia_kg_m2_g")
    assert not is_open_value("lambda") and not is_open_value("attached_inertia_kg_m2")


@pytest.mark.parametrize(
    ("values", "message"),
    [
        ({"te_amplitude_um": -1.0}, "te_amplitude_um: must be in [0, 10000] um"),
        ({"te_amplitude_um_xx": 1.0}, "te_amplitude_um_xx: names no mesh"),
        ({"attached_inertia_kg_m2_q": float("nan")}, "must be in"),
        ({"attached_inertia_kg_m2_z": 1.0}, "names no gear"),
        ({"layout_angle_deg": 400.0}, "must be in [-360, 360] deg"),
    ],
)
def test_bad_open_values_are_one_clear_line(scene, values, message):
    with pytest.raises(InputError, match=None) as err:
        with_open_values(scene, **values)
    assert message in str(err.value) and "\n" not in str(err.value)


def test_values_equal_to_the_scenes_own_derive_nothing(scene):
    # diso.toml states 5 um, 10 kg m^2 and 120 deg; the scene q-braking and "mesh"
    same = with_open_values(
        scene,
        te_amplitude_um=5.0,
        flywheel_inertia_kg_m2=10,
        layout_angle_deg=120.0,
        load_reading="q-braking",
        damping_normalisation="mesh",
    )
    assert same is scene
    assert with_open_values(scene, te_amplitude_um=6.0) is not scene


def test_a_variant_keeps_the_scenes_own_open_values(tmp_path, root):
    text = (root / "scenes" / "reference-light.toml").read_text()
    topo = (root / "scenes" / "topologies" / "diso.toml").as_posix()
    text = text.replace('topology = "topologies/diso.toml"', f'topology = "{topo}"')
    path = tmp_path / "open.toml"
    path.write_text(text.replace("\n[open]\n", "\n[open]\nte_amplitude_um = 8.0\n"))
    own = load_target(path)
    _, p = _model(own, flywheel_inertia_kg_m2=3.0)
    assert p["E_u_1"] == pytest.approx(8.0 / 50.0, rel=1e-12)  # the file's 8 um kept
    assert with_open_values(own, te_amplitude_um=8.0) is own


def test_flywheel_gives_the_reduced_mass_coupling_by_hand(scene):
    # By hand for the reference stage (equal pinions p, q on gear g, equal meshes):
    # W_uu = c^2 (r_p^2/I_p + r_g^2/I_g), W_uv = c^2 r_g^2/I_g, omega_n^2 = k_m W_uu, so
    # kappa_uv = W_uv / W_uu = (r_g^2/I_g) / (r_p^2/I_p + r_g^2/I_g).
    for J in (0.5, 25.0):
        variant = with_open_values(scene, flywheel_inertia_kg_m2=J)
        p_, g = variant.topology.gear("p"), variant.topology.gear("g")
        a, c = p_.base_radius**2 / p_.inertia, g.base_radius**2 / g.inertia
        _, values = _model(scene, flywheel_inertia_kg_m2=J)
        assert values["kappa_u_v"] == pytest.approx(c / (a + c), rel=1e-10)
        assert values["kappa_v_u"] == pytest.approx(c / (a + c), rel=1e-10)


# The sign table of the two readings (SEED.md): f2 < 0 in both; the coupling terms
# kappa_uv, kappa_vu, xi_uv, xi_vu positive with q braking, negative with both driving.
@pytest.mark.parametrize("name", ["reference-light", "reference-heavy"])
def test_the_two_readings_differ_in_the_coupling_signs_only(name):
    base = load_target(resolve_target(name))
    _, braking = _model(base)
    _, driving = _model(base, load_reading="both-driving")
    f1 = base.parameters["f1"]
    lam = base.parameters["lambda"]
    for p in (braking, driving):
        assert p["f_u"] == pytest.approx(f1) and p["f_v"] == pytest.approx(-lam * f1)
    for key in ("kappa_u_v", "kappa_v_u", "xi_u_v", "xi_v_u"):
        assert braking[key] > 0 and driving[key] == pytest.approx(-braking[key], rel=1e-12)
    for key in braking:
        if key not in ("kappa_u_v", "kappa_v_u", "xi_u_v", "xi_v_u"):
            assert driving[key] == pytest.approx(braking[key], rel=1e-12, abs=1e-15), key
    # the shipped scene of the other reading is the same model
    other = derive_model(load_target(resolve_target(f"{name}-both-driving")))
    assert np.allclose(other.defaults, list(driving.values()), rtol=1e-12)


def test_the_load_sign_follows_the_torque_sign():
    # Pinion q driving while v is measured forward (no such built-in reading): f_v > 0,
    # as T_q > 0 loads q's flank; the couplings stay positive.
    from dataclasses import replace

    from gearsym.derive.input.readings import Reading

    base = load_target(resolve_target("reference-light"))
    odd = Reading("q-driving-forward", "", ("p", "q"), (), ())
    topo = replace(base.topology, readings=base.topology.readings | {odd.id: odd})
    from gearsym.derive.input.readings import apply_reading

    scene = replace(base, topology=apply_reading(topo, odd.id, "test"), load_reading=odd.id)
    model = derive_model(scene)
    p = dict(zip(model.parameter_names, model.defaults, strict=True))
    assert p["f_v"] == pytest.approx(base.parameters["lambda"] * base.parameters["f1"])
    assert p["kappa_u_v"] > 0
    assert model.scene.topology.torques["q"] > 0


def test_switching_the_reading_back_leaves_no_trace(scene):
    driving = with_open_values(scene, load_reading="both-driving")
    back = with_open_values(driving, load_reading="q-braking")
    assert [m.orientation for m in back.topology.meshes] == [1, 1]
    assert np.allclose(derive_model(back).defaults, derive_model(scene).defaults, rtol=1e-12)


def test_modal_damping_gives_each_mode_the_damping_ratio(scene):
    # Reference: for equal meshes kappa = [[1, a], [a, 1]] has modes (1, +-1) with
    # frequencies sqrt(1 +- a); modal damping zeta on each gives xi = zeta sqrt(kappa):
    # xi_uu = zeta (sqrt(1+a) + sqrt(1-a)) / 2, xi_uv = zeta (sqrt(1+a) - sqrt(1-a)) / 2.
    _, p = _model(scene, damping_normalisation="modal")
    zeta, a = scene.parameters["damping_ratio"], p["kappa_u_v"]
    plus, minus = math.sqrt(1 + a), math.sqrt(1 - a)
    assert p["xi_u_u"] == pytest.approx(zeta * (plus + minus) / 2, rel=1e-9)
    assert p["xi_u_v"] == pytest.approx(zeta * (plus - minus) / 2, rel=1e-9)
    assert p["xi_v_u"] == pytest.approx(p["xi_u_v"], rel=1e-9)
    _, mesh = _model(scene)
    assert p["xi_u_v"] == pytest.approx(mesh["xi_u_v"] / 2, rel=0.01)  # ~ half of "mesh"


def test_choice_names_are_open_values():
    assert is_open_value("load_reading") and is_open_value("damping_normalisation")
    from gearsym.derive.input.open_values import OPEN_VALUE_BASES

    assert {"load_reading", "te_amplitude_um", "flywheel_inertia_kg_m2"} <= OPEN_VALUE_BASES


@pytest.mark.parametrize(
    ("values", "message"),
    [
        ({"load_reading": "both-drivng"}, "'both-drivng' is not a reading of topology 'diso'"),
        ({"load_reading": 1.0}, "load_reading: must be text"),
        ({"damping_normalisation": "modl"}, "(did you mean 'modal'?)"),
    ],
)
def test_bad_choices_are_one_clear_line(scene, values, message):
    with pytest.raises(InputError) as err:
        with_open_values(scene, **values)
    assert message in str(err.value) and "\n" not in str(err.value)


def test_cli_set_takes_open_values_with_text(capsys):
    import json

    from gearsym.cli import main

    args = ["derive", "reference-light", "--dry-run", "--json"]
    code = main(args + ["--set", "load_reading=both-driving", "--set", "te_amplitude_um=10"])
    out = json.loads(capsys.readouterr().out)
    (model,) = out.values()
    assert code == 0 and model["kappa"]["uv"]["mean"] < 0 and model["f"]["v"] < 0
    assert model["transmission_error"]["v"]["amplitude"] == [pytest.approx(10.0 / 50.0)]
    code = main(args[:-1] + ["--set", "damping_normalisation=modl"])
    err = capsys.readouterr().err
    assert code == 2 and err.count("\n") == 1 and "(did you mean 'modal'?)" in err


def test_load_with_the_scenes_own_values_uses_the_shipped_module():
    import gearsym

    system = gearsym.load("reference-light", load_reading="q-braking", te_amplitude_um=5.0)
    assert system.module.__name__ == "gearsym.generated.reference_light"
