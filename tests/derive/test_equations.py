"""The derived DI-SO model against an independent hand derivation.

Reference: Newton's second law written out by hand below for three rigid gears in
NumPy (no SymPy), with the mesh deflection x = cos(beta_b)(r_p theta_p - r_g theta_g) + e
and force F = k(t) b g(x/b) + c x'.  The generated right-hand side must give the same
non-dimensional acceleration u'' = x'' / (b omega_n^2) at the matching state.  In the
both-driving reading the q-g coordinate is measured the other way: v = -x_qg / b by hand.
"""

import math

import numpy as np
import pytest
import sympy as sp
from gearsym.solver import load_generated


def hand_compliance(topo):
    p, q, g = (topo.gear(i) for i in "pqg")
    c = math.cos(topo.meshes[0].pair.driver.base_helix_angle)
    w11 = c**2 * (p.base_radius**2 / p.inertia + g.base_radius**2 / g.inertia)
    w22 = c**2 * (q.base_radius**2 / q.inertia + g.base_radius**2 / g.inertia)
    w12 = c**2 * g.base_radius**2 / g.inertia
    return np.array([[w11, w12], [w12, w22]])


def test_form_and_coupling_terms_of_the_study(light_model):
    names = set(light_model.parameter_names)
    # The study's form has xi11, xi12, xi21, xi22 and kappa11..kappa22.
    for i in "uv":
        for j in "uv":
            assert f"xi_{i}_{j}" in names and f"kappa_{i}_{j}" in names
    assert light_model.states == ("u", "v", "du", "dv")


def test_mean_coefficients_against_hand_formulas(diso_model):
    topo = diso_model.scene.topology
    W = hand_compliance(topo)
    km = [m.stiffness.mean for m in topo.meshes]
    b = [m.half_backlash for m in topo.meshes]
    zeta = diso_model.scene.damping_ratio
    wn2 = km[0] * W[0, 0]
    values = dict(zip(diso_model.parameter_names, diso_model.defaults, strict=True))
    for i, ci in enumerate("uv"):
        for j, cj in enumerate("uv"):
            kappa = W[i, j] * b[j] * km[j] / (b[i] * wn2)
            c_j = 2 * zeta * math.sqrt(km[j] / W[j, j])
            xi = W[i, j] * c_j * b[j] / (2 * b[i] * math.sqrt(wn2))
            assert values[f"kappa_{ci}_{cj}"] == pytest.approx(kappa, rel=1e-12)
            assert values[f"xi_{ci}_{cj}"] == pytest.approx(xi, rel=1e-12)
    assert values["kappa_u_u"] == pytest.approx(1.0, rel=1e-14)
    assert values["xi_u_u"] == pytest.approx(zeta, rel=1e-14)
    assert diso_model.scales["omega_n_rad_per_s"] == pytest.approx(math.sqrt(wn2), rel=1e-13)


@pytest.mark.parametrize("name", ["diso", "reference_light", "reference_light_both_driving"])
def test_generated_rhs_equals_hand_newton(name, diso_model, light_model, root):
    if name == "reference_light_both_driving":
        from gearsym.derive import derive_model, load_target

        model = derive_model(load_target(root / "scenes" / "reference-light-both-driving.toml"))
    else:
        model = {"diso": diso_model, "reference_light": light_model}[name]
    mod = load_generated(name)
    # s = +1: v measured forward (q's flank loaded); -1: measured the other way (g's flank)
    s = -1.0 if name.endswith("both_driving") else 1.0
    topo = model.scene.topology
    p, q, g = (topo.gear(i) for i in "pqg")
    meshes = topo.meshes
    cb = [math.cos(m.pair.driver.base_helix_angle) for m in meshes]
    b = [m.half_backlash for m in meshes]
    wn = model.scales["omega_n_rad_per_s"]
    omega = dict(zip(model.parameter_names, model.defaults, strict=True))["omega"]
    we = omega * wn
    zeta = model.scene.damping_ratio
    W = hand_compliance(topo)
    damp = [2 * zeta * math.sqrt(meshes[j].stiffness.mean / W[j, j]) for j in range(2)]
    coeff = model.scene.features.backlash.coefficients  # g1, g3, g5, g7 by power
    H = model.scene.features.stiffness_harmonics

    def gfun(x):
        return sum(a * x ** (2 * k + 1) for k, a in enumerate(coeff))

    def k_of(j, t):
        s = meshes[j].stiffness
        arg = we * t - meshes[j].phase
        return s.mean + sum(
            s.cos[h - 1] * math.cos(h * arg) + s.sin[h - 1] * math.sin(h * arg)
            for h in range(1, H + 1)
        )

    def e_of(j, t, d):
        te = meshes[j].transmission_error
        arg = we * t - meshes[j].phase
        tot = 0.0
        for h, (a, ph) in enumerate(zip(te.amplitudes, te.phases, strict=True), start=1):
            tot += a * (h * we) ** d * math.cos(h * arg + ph + d * math.pi / 2)
        return tot

    if model.scene.loads is None:
        torque = {gid: topo.torques.get(gid, 0.0) for gid in "pqg"}
        extra = [0.0, 0.0]
    else:
        # The scene gives the size of f: no torques, and f enters u'' as itself.  Its sign
        # by hand: p drives (its torque loads x_pg forward, +); q brakes (T_q < 0 unloads
        # x_qg: -) or drives (T_q > 0 loads x_qg, +, but v = -x_qg / b: -) -- f_v < 0 both ways.
        torque = {"p": 0.0, "q": 0.0, "g": 0.0}
        extra = [model.scene.loads["u"], -model.scene.loads["v"]]

    rng = np.random.default_rng(7)
    for _ in range(25):
        t = rng.uniform(0, 5e-3)
        th = rng.uniform(-1e-3, 1e-3, 3)  # theta_p, theta_q, theta_g (rad)
        dth = rng.uniform(-0.5, 0.5, 3)
        rp, rq, rg = p.base_radius, q.base_radius, g.base_radius
        x = [
            cb[0] * (rp * th[0] - rg * th[2]) + e_of(0, t, 0),
            cb[1] * (rq * th[1] - rg * th[2]) + e_of(1, t, 0),
        ]
        dx = [
            cb[0] * (rp * dth[0] - rg * dth[2]) + e_of(0, t, 1),
            cb[1] * (rq * dth[1] - rg * dth[2]) + e_of(1, t, 1),
        ]
        F = [k_of(j, t) * b[j] * gfun(x[j] / b[j]) + damp[j] * dx[j] for j in range(2)]
        ddp = (torque["p"] - rp * cb[0] * F[0]) / p.inertia
        ddq = (torque["q"] - rq * cb[1] * F[1]) / q.inertia
        ddg = (torque["g"] + rg * cb[0] * F[0] + rg * cb[1] * F[1]) / g.inertia
        ddx = [
            cb[0] * (rp * ddp - rg * ddg) + e_of(0, t, 2),
            cb[1] * (rq * ddq - rg * ddg) + e_of(1, t, 2),
        ]
        sign = [1.0, s]
        expected = [sign[j] * ddx[j] / (b[j] * wn**2) + extra[j] for j in range(2)]
        state = np.array(
            [x[0] / b[0], s * x[1] / b[1], dx[0] / (b[0] * wn), s * dx[1] / (b[1] * wn)]
        )
        got = mod.rhs(wn * t, state, np.array(mod.DEFAULTS))
        assert got[0] == pytest.approx(state[2], rel=1e-14)
        assert got[2:] == pytest.approx(expected, rel=1e-9, abs=1e-12)


def test_rigid_body_mode_is_absent(diso_model):
    eq = diso_model.nondim.equations
    for e in eq.reduced:
        assert not e.has(*eq.theta)
    # W is symmetric (Maxwell-Betti reciprocity of the mesh compliances).
    assert sp.simplify(eq.compliance - eq.compliance.T) == sp.zeros(2, 2)


def test_added_input_gear_adds_a_coordinate(root):
    from gearsym.derive import derive_model, load_target

    tiso = derive_model(load_target(root / "scenes" / "topologies" / "tiso.toml"))
    assert tiso.coordinates == ("u", "v", "w")
    assert len(tiso.states) == 6
