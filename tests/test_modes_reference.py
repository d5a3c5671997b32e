"""Natural frequencies of a helical pair on isotropic bearings against a hand-assembled model.

Issue 15: the frequencies of ``gearsym modes helical-pair-bearings`` equal an independent
eigen-analysis of a mass and stiffness matrix assembled by hand, to 1e-8.  This file is the
independent side: it was written without reading the derivation
(derive/equations/structure.py) or the modes analysis, and takes only data (masses,
inertias, base radii, stiffnesses, angles) from the topology loader.

Model (8 degrees of freedom q = theta_p, theta_g, x_p, y_p, z_p, x_g, y_g, z_g): each gear a
rigid body of mass m and polar inertia I on a bearing (k_r along x and y, k_a along z); the
mesh one spring k_m along the normal line of action, compressed by

    delta = cos(beta_b) (r_bp theta_p + r_bg theta_g + (x_p - x_g, y_p - y_g) . n_t)
            + sin(beta_b) (z_p - z_g),

rotations each positive in its own turning direction and n_t the unit transverse vector
along the line of action.  With delta = a . q, V = 1/2 k_m (a . q)^2 + bearing springs and
T = 1/2 q'^T M q', so K = k_m a a^T + diag(0, 0, k_r, k_r, k_a, k_r, k_r, k_a) and
M = diag(I_p, I_g, m_p, m_p, m_p, m_g, m_g, m_g); K v = omega^2 M v.
"""

import json

import numpy as np
import pytest
import scipy.linalg
from gearsym.cli import main
from gearsym.derive.input.scene import builtin_root
from gearsym.derive.input.topology import load_topology

# Double-precision symmetric eigensolvers on an 8x8 problem this well conditioned agree to
# about 1e-12 relative, so 1e-8 (the tolerance) leaves room only for rounding, not
# for a wrong sign, a missing cos(beta_b) or a misplaced inertia (those move a frequency
# by percent).
RTOL = 1e-8


def helical_pair():
    """The data of helical-pair-bearings.toml as a plain dict (SI units, radians)."""
    t = load_topology(builtin_root() / "topologies" / "helical-pair-bearings.toml")
    p, g = t.gear("p"), t.gear("g")
    mesh = t.meshes[0]
    bp, bg = t.bearings["p"], t.bearings["g"]
    return {
        "I_p": p.inertia,
        "I_g": g.inertia,
        "m_p": p.mass,
        "m_g": g.mass,
        "r_bp": p.base_radius,
        "r_bg": g.base_radius,
        "k_m": mesh.stiffness.mean,
        "beta_b": mesh.pair.driver.base_helix_angle,
        "alpha": mesh.pair.working_pressure_angle,
        "position": mesh.driver_position,
        "k_rp": bp.radial,
        "k_ap": bp.axial,
        "k_rg": bg.radial,
        "k_ag": bg.axial,
    }


def assemble(d, *, line_angle=None, bearing=None):
    """Mass and stiffness matrices (8x8) of the helical pair, by hand.

    Parameters
    ----------
    d : dict
        From `helical_pair`.
    line_angle : float, optional
        Direction of n_t in the transverse plane (rad, from x).  Default: the line of
        action of a pinion above the gear (driver_position), inclined by the working
        pressure angle -- one plausible layout; with isotropic bearings any angle gives
        the same frequencies.
    bearing : float, optional
        If given, every bearing stiffness (radial and axial, N/m) is replaced by it.

    Returns
    -------
    M, K : ndarray, shape (8, 8)
        kg and kg m^2 on the diagonal of M; N/m, N and N m/rad in K.
    """
    if line_angle is None:
        line_angle = d["position"] - np.pi / 2 + d["alpha"]
    k_rp, k_ap, k_rg, k_ag = (
        (d["k_rp"], d["k_ap"], d["k_rg"], d["k_ag"]) if bearing is None else (bearing,) * 4
    )
    c, s = np.cos(d["beta_b"]), np.sin(d["beta_b"])
    nx, ny = np.cos(line_angle), np.sin(line_angle)
    a = np.array(
        [c * d["r_bp"], c * d["r_bg"], c * nx, c * ny, s, -c * nx, -c * ny, -s],
    )
    K = d["k_m"] * np.outer(a, a) + np.diag([0, 0, k_rp, k_rp, k_ap, k_rg, k_rg, k_ag])
    M = np.diag([d["I_p"], d["I_g"]] + [d["m_p"]] * 3 + [d["m_g"]] * 3)
    return M, K


def natural_frequencies(M, K):
    """The 7 nonzero natural frequencies (Hz, ascending) of K v = omega^2 M v.

    The zero eigenvalue (the pair turning rigidly, r_bp theta_p = -r_bg theta_g, nothing
    else moving) is checked and dropped.
    """
    w2 = scipy.linalg.eigh(K, M, eigvals_only=True)
    assert abs(w2[0]) < 1e-12 * w2[-1], "no rigid-body mode: the assembly is wrong"
    assert w2[1] > 1e-6 * w2[-1]
    return np.sqrt(w2[1:]) / (2 * np.pi)


def test_frequencies_do_not_depend_on_the_direction_of_the_line_of_action():
    # Isotropic bearings and masses: turning n_t is a rotation of both gears' (x, y)
    # together, an orthogonal change of coordinates that leaves M and the bearings alone.
    d = helical_pair()
    reference = natural_frequencies(*assemble(d))
    for angle in (0.0, 0.3, 1.234, -2.5, np.pi):
        np.testing.assert_allclose(
            natural_frequencies(*assemble(d, line_angle=angle)), reference, rtol=1e-12
        )


def test_stiff_bearings_leave_the_torsional_pair():
    # Closed form: the two-inertia torsional gear pair reduced to the line of action
    # (Ozguven & Houser, "Mathematical models used in gear dynamics -- a review", J. Sound
    # Vib. 121(3), 1988, single-degree-of-freedom model with equivalent mass
    # 1/m_e = r_bp^2/I_p + r_bg^2/I_g), the helical mesh seen through cos^2(beta_b):
    #     omega^2 = k_m cos^2(beta_b) (r_bp^2/I_p + r_bg^2/I_g).
    # Bearings of 1e14 N/m are 1e5 times the mesh, so the lateral and axial compliance
    # (in series with the mesh) shifts it by about 1e-5.
    d = helical_pair()
    f = natural_frequencies(*assemble(d, bearing=1e14))
    inverse_equivalent_mass = d["r_bp"] ** 2 / d["I_p"] + d["r_bg"] ** 2 / d["I_g"]
    closed = np.sqrt(d["k_m"] * np.cos(d["beta_b"]) ** 2 * inverse_equivalent_mass) / (2 * np.pi)
    assert f[0] == pytest.approx(closed, rel=1e-4)
    assert f[1] > 50 * f[0]  # every other mode is a bearing mode, far above


def test_gearsym_modes_matches_the_hand_assembled_model(capsys):
    code = main(["modes", "helical-pair-bearings", "--json"])
    out = capsys.readouterr()
    assert code == 0, out.err
    modes = json.loads(out.out)["modes"]
    assert [m["index"] for m in modes] == list(range(8))
    assert modes[0]["label"] == "rigid-body"
    theirs = np.array([m["frequency_hz"] for m in modes])
    ours = natural_frequencies(*assemble(helical_pair()))
    assert abs(theirs[0]) <= 1e-8 * ours[-1]
    np.testing.assert_allclose(theirs[1:], ours, rtol=RTOL)
