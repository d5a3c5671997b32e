"""Natural frequencies of a tilting helical pair on bearings against a hand-assembled model.

The frequencies of ``gearsym modes`` for helical-pair-bearings.toml with
``degrees_of_freedom = "lateral-torsional-axial-tilting"`` equal an independent
eigen-analysis of a 12x12 mass and stiffness matrix assembled here from vectors, to 1e-8.
This file is the independent side: it was written without reading the derivation
(derive/equations/structure.py, derive/emit/audit_structure.py) or the modes analysis, and
takes only data (masses, inertias, base radii, stiffnesses, angles) from the topology loader.

Model (12 degrees of freedom, per gear k = p, g: theta_k, x_k, y_k, z_k, a_k, c_k).  Each
gear is a rigid body of mass m, polar inertia I and diametral inertia J on a bearing (k_r
along x and y, k_a along z, k_t about x and y).  Frame: z along both shafts, g's centre at
the origin, p's at a_w (cos phi, sin phi, 0) with a_w = r_wp + r_wg, r_w = r_b / cos(alpha_wt)
and phi the driver position.  The contact C is the pitch point r_wg (cos phi, sin phi, 0).
The normal line of action is

    n = cos(beta_b) n_t + s_z sin(beta_b) e_z,

n_t the transverse unit vector tangent to both base circles through C, directed so that the
force p exerts on g turns g in its operating (clockwise) sense and pushes it away from p.
Gear k's small-rotation vector is rot_k = (a_k, c_k, eps_k theta_k), eps_p = +1, eps_g = -1
(each theta positive in its gear's operating direction), the material point of gear k at C
moves by u_k = X_k + rot_k x (C - O_k), and the mesh, one spring k_m along n, is compressed
by delta = n . (u_p - u_g) = w . q.  Then

    V = 1/2 k_m (w . q)^2 + sum_k 1/2 (k_r (x_k^2 + y_k^2) + k_a z_k^2 + k_t (a_k^2 + c_k^2)),
    T = 1/2 sum_k (I_k theta_k'^2 + m_k |X_k'|^2 + J_k (a_k'^2 + c_k'^2)),

so K = k_m w w^T + diag(bearings), M = diag(I, m, m, m, J, J) per gear, and K v = omega^2 M v
(Lagrange's equations of an undamped linear system, e.g. Meirovitch, "Fundamentals of
Vibrations", 2001, ch. 7).
"""

import json

import numpy as np
import pytest
import scipy.linalg
from gearsym.cli import main
from gearsym.derive.input.scene import builtin_root
from gearsym.derive.input.topology import load_topology

# Double-precision symmetric eigensolvers on a 12x12 problem this well conditioned agree to
# about 1e-12 relative, so 1e-8 leaves room only for rounding, not for a wrong lever arm, a
# missing sin(beta_b) or a misplaced inertia (those move a frequency by percent).
RTOL = 1e-8

TOPOLOGY = builtin_root() / "topologies" / "helical-pair-bearings.toml"

# Coordinate order of the hand assembly: gear p's six, then gear g's six.
GEARS = ("p", "g")
PER_GEAR = ("theta", "x", "y", "z", "a", "c")
EPS = {"p": 1.0, "g": -1.0}  # sign of theta in the rotation about +z (operating sense)


def helical_pair():
    """The data of helical-pair-bearings.toml as a plain dict (SI units, radians)."""
    t = load_topology(TOPOLOGY)
    mesh = t.meshes[0]
    d = {
        "k_m": mesh.stiffness.mean,
        "beta_b": mesh.pair.driver.base_helix_angle,
        "alpha": mesh.pair.working_pressure_angle,
        "phi": mesh.driver_position,
    }
    for k in GEARS:
        gear, bearing = t.gear(k), t.bearings[k]
        d[k] = {
            "m": gear.mass,
            "I": gear.inertia,
            "J": gear.diametral_inertia,
            "r_b": gear.base_radius,
            "k_r": bearing.radial,
            "k_a": bearing.axial,
            "k_t": bearing.tilt,
        }
    return d


def geometry(d, *, phi, beta_b, s_z):
    """Centres O_p, O_g, contact point C and normal n (each shape (3,), m or unitless)."""
    r_wp = d["p"]["r_b"] / np.cos(d["alpha"])
    r_wg = d["g"]["r_b"] / np.cos(d["alpha"])
    e_c = np.array([np.cos(phi), np.sin(phi), 0.0])  # from g's centre towards p's
    e_z = np.array([0.0, 0.0, 1.0])
    t = np.cross(e_z, e_c)  # counter-clockwise tangent of g's pitch circle at C
    centre = {"g": np.zeros(3), "p": (r_wp + r_wg) * e_c}
    C = r_wg * e_c
    # Force on g along n_t: its torque about O_g is r_wg (n_t . t) e_z, negative (clockwise,
    # g's operating sense) for n_t . t < 0; its radial part -sin(alpha) e_c pushes g away
    # from p.  The line through C then lies r_wg cos(alpha) = r_bg from O_g and
    # r_wp cos(alpha) = r_bp from O_p: tangent to both base circles.
    n_t = -np.cos(d["alpha"]) * t - np.sin(d["alpha"]) * e_c
    n = np.cos(beta_b) * n_t + s_z * np.sin(beta_b) * e_z
    return centre, C, n


def deflection(q, centre, C, n):
    """delta = n . (u_p - u_g) for generalised coordinates q (shape (12,)), m."""
    u = {}
    for i, k in enumerate(GEARS):
        theta, x, y, z, a, c = q[6 * i : 6 * i + 6]
        rot = np.array([a, c, EPS[k] * theta])
        u[k] = np.array([x, y, z]) + np.cross(rot, C - centre[k])
    return n @ (u["p"] - u["g"])


def assemble(d, *, phi=None, beta_b=None, s_z=1.0):
    """Mass and stiffness matrices (12x12) of the tilting helical pair, by hand.

    Parameters
    ----------
    d : dict
        From `helical_pair`.
    phi : float, optional
        Angle of p's centre round g's centre (rad, from +x).  Default: the topology's
        driver position.
    beta_b : float, optional
        Base helix angle (rad).  Default: the topology's.
    s_z : {1.0, -1.0}
        Sign of the axial component of n (the helix hand).

    Returns
    -------
    M, K : ndarray, shape (12, 12)
        kg and kg m^2 on the diagonal of M; N/m, N and N m/rad in K.
    """
    phi = d["phi"] if phi is None else phi
    beta_b = d["beta_b"] if beta_b is None else beta_b
    centre, C, n = geometry(d, phi=phi, beta_b=beta_b, s_z=s_z)
    # delta is linear in q, so unit perturbations give its gradient exactly (to rounding).
    w = np.array([deflection(e, centre, C, n) for e in np.eye(12)])
    stiff, mass = [], []
    for k in GEARS:
        g = d[k]
        stiff += [0.0, g["k_r"], g["k_r"], g["k_a"], g["k_t"], g["k_t"]]
        mass += [g["I"], g["m"], g["m"], g["m"], g["J"], g["J"]]
    K = d["k_m"] * np.outer(w, w) + np.diag(stiff)
    return np.diag(mass), K


def natural_frequencies(M, K):
    """The 11 nonzero natural frequencies (Hz, ascending) of K v = omega^2 M v.

    The zero eigenvalue (the pair turning rigidly, r_bp theta_p = r_bg theta_g, nothing else
    moving) is checked and dropped.
    """
    w2 = scipy.linalg.eigh(K, M, eigvals_only=True)
    assert abs(w2[0]) < 1e-12 * w2[-1], "no rigid-body mode: the assembly is wrong"
    assert w2[1] > 1e-6 * w2[-1]
    return np.sqrt(w2[1:]) / (2 * np.pi)


def test_the_rigid_rotation_does_not_deflect_the_mesh():
    # Kinematics (base-circle rolling, r_bp theta_p = r_bg theta_g with each theta in its
    # gear's turning sense): a check of the sign of n_t and of eps before any eigenvalue.
    d = helical_pair()
    centre, C, n = geometry(d, phi=d["phi"], beta_b=d["beta_b"], s_z=1.0)
    q = np.zeros(12)
    q[0], q[6] = 1 / d["p"]["r_b"], 1 / d["g"]["r_b"]
    assert abs(deflection(q, centre, C, n)) < 1e-12
    q[6] = 0.0  # the driver alone, advancing, compresses the mesh
    assert deflection(q, centre, C, n) == pytest.approx(np.cos(d["beta_b"]), rel=1e-12)


def test_helix_hand_does_not_change_the_frequencies():
    # Mirror symmetry z -> -z (z_k, a_k, c_k change sign; M and the bearings are unchanged)
    # maps the model with s_z = +1 onto the one with s_z = -1.
    d = helical_pair()
    np.testing.assert_allclose(
        natural_frequencies(*assemble(d, s_z=-1.0)),
        natural_frequencies(*assemble(d, s_z=1.0)),
        rtol=1e-12,
    )


def test_frequencies_do_not_depend_on_the_direction_of_the_centre_line():
    # Isotropic bearings and masses: turning the layout about z rotates both gears' (x, y)
    # and (a, c) together, an orthogonal change of coordinates that leaves M and the
    # bearings alone.
    d = helical_pair()
    reference = natural_frequencies(*assemble(d))
    np.testing.assert_allclose(
        natural_frequencies(*assemble(d, phi=d["phi"] + 1.1)), reference, rtol=1e-12
    )


def test_spur_pair_tilting_modes_are_the_bearing_alone():
    # Closed form: with beta_b = 0, n lies in the plane z = 0 through C, so the lever
    # arm (C - O_k) x n is along z and no tilt enters delta; each tilt is an uncoupled
    # oscillator J a'' + k_t a = 0, omega^2 = k_t / J, twice per gear (about x and about y).
    d = helical_pair()
    f = natural_frequencies(*assemble(d, beta_b=0.0))
    for k in GEARS:
        closed = np.sqrt(d[k]["k_t"] / d[k]["J"]) / (2 * np.pi)
        assert np.sum(np.isclose(f, closed, rtol=1e-12, atol=0.0)) == 2, (k, closed, f)
    # The helix couples the tilt about the tangent t = e_z x e_c (its lever arm
    # (C - O_k) x n = sin(beta_b) (C - O_k) x e_z is along t) but not the tilt about the
    # centre line e_c, which moves no point of the centre line: exactly one of each gear's
    # two tilting modes stays at the closed form.
    f_helical = natural_frequencies(*assemble(d))
    for k in GEARS:
        closed = np.sqrt(d[k]["k_t"] / d[k]["J"]) / (2 * np.pi)
        assert np.sum(np.isclose(f_helical, closed, rtol=1e-12, atol=0.0)) == 1, (k, f_helical)


def test_gearsym_modes_matches_the_hand_assembled_model(tmp_path, monkeypatch, capsys):
    monkeypatch.setenv("GEARSYM_CACHE", str(tmp_path / "cache"))
    scene = tmp_path / "tilting-pair.toml"
    scene.write_text(
        "[scene]\n"
        'name = "tilting-pair"\n'
        f"topology = {json.dumps(str(TOPOLOGY.resolve()))}\n"
        "[features]\n"
        'degrees_of_freedom = "lateral-torsional-axial-tilting"\n'
        "[parameters]\n"
        "omega = 0.5\n"
        "damping_ratio = 0.03\n"
    )
    code = main(["modes", str(scene), "--json"])
    out = capsys.readouterr()
    assert code == 0, out.err
    modes = json.loads(out.out)["modes"]
    assert [m["index"] for m in modes] == list(range(12))
    assert modes[0]["label"] == "rigid-body"
    theirs = np.array([m["frequency_hz"] for m in modes])
    ours = natural_frequencies(*assemble(helical_pair()))
    assert abs(theirs[0]) <= 1e-8 * ours[-1]
    np.testing.assert_allclose(theirs[1:], ours, rtol=RTOL)
