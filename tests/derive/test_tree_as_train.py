"""The shipped DI-SO through both derivations (issue 26, "the tree models of today give
identical equations through the new derivation").

The tree derivation (``derive/equations/torsion.py``: Newton's law per gear, the rigid-body
rotation eliminated by differentiating the mesh deflections, the study's mesh coordinates
u and v) and the derivation in body coordinates (``derive/equations/train.py`` and
``body_dynamics.py``: each gear's rotation ``r theta``, the rigid-body rotation removed by
the momentum pivot) are independent code paths.  The same DI-SO written as a ``[train]``
file -- the tree model's own inertias, effective base radii ``r_b cos(beta_b)`` (the
helical mesh's transverse lever arm), mean stiffnesses, stiffness harmonics, layout phase,
half backlashes, damping ratio, torques and transmission errors -- must give the same
accelerations of the mesh deflections at any state, time and load: the tree model's
``u'', v''`` against ``D ybar'' + e''`` of the body model (``D`` its meshes' rows over its
coordinates, ``e`` the transmission error that the tree's u and v include and the body
model's deflections do not).

One convention differs and is stated here rather than hidden: the tree adds a mesh's
transmission error to its deflection as it is (``x = ... + e``), the body model as excess
material on the loaded flank (``x = ... + s e``, ``s`` the sign of the static deflection).
Pinion q brakes (``q-braking``): its mesh is loaded on the back flank, ``s = -1``, so the
tree model is given that mesh's error half a turn later (``te_phase_deg_qg = 180``,
``cos(x + pi) = -cos x``).

The body derivation models backlash as the exact dead zone only, so the scene compared is
``reference-dead-zone``; the study's polynomial fit (``reference-light``) has no body form.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from gearsym.resolve import load, planetary_system

SCENE = "reference-dead-zone"
TORQUES = {"p": 400.0, "q": -50.0}  # N m in each pinion's operating sense
MESH_HZ = 880.0  # p's 50 teeth at 1,056 rpm


def _train_text(tree) -> str:
    """The tree model's DI-SO as a [train] file (its own numbers, full precision)."""
    st, mod = tree.module.STRUCTURE, tree.module
    names = {k: float(v) for k, v in zip(mod.PARAMETERS, tree.p, strict=True)}
    r = {g: float(-min(row) if g == "g" else max(row)) for g, row in _columns(st).items()}
    teeth = {"p": 50, "q": 50, "g": 100}
    inertia = {g: float(m) for g, m in zip(("p", "q", "g"), st["mass"], strict=True)}
    body = "".join(
        f'[[train.body]]\nid = "{g}"\nteeth = {teeth[g]}\n'
        f"base_radius_mm = {r[g] * 1e3!r}\ninertia_kg_m2 = {inertia[g]!r}\n\n"
        for g in ("p", "q", "g")
    )
    mesh = ""
    for j, (coord, gears, phase) in enumerate(
        (("u", '["p", "g"]', 0.0), ("v", '["q", "g"]', 1.0 / 3.0))
    ):
        waves = ", ".join(
            f"[{names[f'kc_{coord}_{h}']!r}, {names[f'ks_{coord}_{h}']!r}]" for h in (1, 2, 3)
        )
        mesh += (
            f'[[train.mesh]]\nid = "{st["owners"][j]}"\ngears = {gears}\n'
            f"stiffness_N_per_m = {float(st['stiffness'][j])!r}\nhalf_backlash_um = 50\n"
            f"variation = [{waves}]\nphase = {phase!r}\n"
            "transmission_error = { amplitude_um = [5.0], phase_deg = [0.0] }\n\n"
        )
    # the gear's torque in the train's one sense of rotation: g turns against p and q
    load_g = 2.0 * (TORQUES["p"] + TORQUES["q"])  # no power into the rigid rotation
    torque = "".join(
        f'[[train.torque]]\nbody = "{g}"\ntorque_Nm = {t!r}\n\n'
        for g, t in (("p", TORQUES["p"]), ("q", TORQUES["q"]), ("g", load_g))
    )
    return (
        '[topology]\nname = "diso-as-train"\ndescription = "the DI-SO in body coordinates"\n\n'
        f"{body}{mesh}{torque}"
        f"[train.dynamics]\nmesh_frequency_hz = {MESH_HZ!r}\ndamping_ratio = 0.03\n"
    )


def _columns(st) -> dict:
    """Each gear's column of the tree's incidence (its lever arm on each mesh, signed)."""
    R = np.asarray(st["incidence"])
    return {g: R[:, k] for k, g in enumerate(("p", "q", "g"))}


@pytest.fixture(scope="module")
def pair(tmp_path_factory):
    tree = load(SCENE)
    tree = tree.with_values(
        speed_rpm=MESH_HZ * 60.0 / 50.0,
        torque_Nm_p=TORQUES["p"],
        torque_Nm_q=TORQUES["q"],
        torque_Nm_g=-2.0 * (TORQUES["p"] + TORQUES["q"]),
        te_phase_deg_qg=180.0,
    )
    path = tmp_path_factory.mktemp("train") / "diso-as-train.toml"
    path.write_text(_train_text(tree), encoding="utf-8")
    return tree, planetary_system(path)


def test_the_two_derivations_share_their_scales(pair):
    tree, body = pair
    assert body.module.OMEGA_N == pytest.approx(tree.module.OMEGA_N, rel=1e-12)
    assert body.module.LENGTH_M == pytest.approx(50e-6, rel=1e-12)
    w_tree = tree.parameter("omega")
    w_body = dict(zip(body.module.PARAMETERS, body.p, strict=True))["omega"]
    assert w_body == pytest.approx(w_tree, rel=1e-12)
    assert w_tree == pytest.approx(2 * math.pi * MESH_HZ / tree.module.OMEGA_N, rel=1e-12)


def _errors(tree, tau: float) -> np.ndarray:
    """(e, e', e'') of u and v at tau, in half backlashes, from the tree's parameters (its
    section 7: E_u cos(w tau + psi_u), E_v cos(w tau - phi_v + psi_v))."""
    p = dict(zip(tree.module.PARAMETERS, tree.p, strict=True))
    w = p["omega"]
    out = np.zeros((3, 2))
    for k, (E, arg) in enumerate(
        (
            (p["E_u_1"], w * tau + p["psi_u_1"]),
            (p["E_v_1"], w * tau - p["phi_v"] + p["psi_v_1"]),
        )
    ):
        out[:, k] = (E * math.cos(arg), -E * w * math.sin(arg), -E * w * w * math.cos(arg))
    return out


@pytest.mark.parametrize("f_scale", [1.0, 0.1, 3.0])
def test_the_dead_zone_diso_has_the_same_accelerations_in_body_coordinates(pair, f_scale):
    """At 200 random states (in contact, apart, on either flank) and times, the tree
    model's u'', v'' against the body model's, its load scaled by ``f_scale`` on both
    (the tree through its torques, the body model through its load factor)."""
    tree, body = pair
    if f_scale != 1.0:
        tree = tree.with_values(
            torque_Nm_p=f_scale * TORQUES["p"],
            torque_Nm_q=f_scale * TORQUES["q"],
            torque_Nm_g=-2.0 * f_scale * (TORQUES["p"] + TORQUES["q"]),
        )
        body = body.with_values(f=f_scale)
    mod = body.module
    D = np.array([mod.MESHES[m]["row"] for m in ("pg", "qg")])  # u_j = D ybar
    assert D.shape == (2, 2) and mod.PIVOT is not None
    rng = np.random.default_rng(26)
    worst, scale = 0.0, 0.0
    for _ in range(200):
        x = rng.normal(size=4) * np.array([2.0, 2.0, 1.0, 1.0])
        tau = rng.uniform(0.0, 100.0)
        e = _errors(tree, tau)
        y = np.linalg.solve(D, x[:2] - e[0])
        dy = np.linalg.solve(D, x[2:] - e[1])
        theirs = D @ mod.rhs(tau, np.concatenate([y, dy]), body.p)[2:] + e[2]
        ours = tree.module.rhs(tau, x, tree.p)[2:]
        worst = max(worst, float(np.max(np.abs(theirs - ours))))
        scale = max(scale, float(np.max(np.abs(ours))))
    assert worst < 1e-13 * scale  # measured: 5e-15 of accelerations of about 7
