"""The audit page's section on internal meshes (a pinion driving a ring), and the index
page's paragraph on internal gears: the ring's geometry, the turning senses and the sign of
the deflection, the mean mesh force and the stiffness method, from the same SymPy objects
as the code (``derive/mesh/internal.py``, ``derive/equations/torsion.py``)."""

from __future__ import annotations

import math

import numpy as np
import sympy as sp

from ..mesh.internal import _trochoid_margin
from .markdown import latex
from .markdown import math_block as _math
from .markdown import number as _num

__all__ = ["INDEX_SECTION", "internal_section"]

INDEX_SECTION = (
    "## Internal gears (rings)\n\n"
    "A gear with `internal = true` is a ring (`derive/mesh/internal.py`): tip circle "
    "$r_a = r - (1 - x)m_n$ inside the reference circle, root circle $r_f = r + (h_f^* + "
    "x)m_n$; a pinion driving it runs at $a_w = (r_2 - r_1)\\cos\\alpha_t/\\cos\\alpha_{wt}$ "
    "with $\\mathrm{inv}\\,\\alpha_{wt} = \\mathrm{inv}\\,\\alpha_t + 2\\tan\\alpha_n(x_2 - x_1)"
    "/(z_2 - z_1)$, and $\\varepsilon_\\alpha = (\\sqrt{r_{a1}^2 - r_{b1}^2} - "
    "\\sqrt{r_{a2}^2 - r_{b2}^2} + a_w\\sin\\alpha_{wt})/p_{bt}$ (ISO 21771; trochoid "
    "interference by SDP/SI's eq. 5-6). Pinion and ring turn the same way (speed ratio "
    "$+z_1/z_2$). Because each $\\theta_k$ is counted in its gear's own operating direction, "
    "$A$ has $+r_{b}$ for the driver and $-r_{b}$ for the driven gear for both kinds of "
    "mesh; in one frame for all gears ($\\varphi_k = \\epsilon_k\\theta_k$, $\\epsilon_k$ the "
    "turning sense) the deflection is $r_{b1}\\varphi_1 + r_{b2}\\varphi_2$ for an external "
    "pair and $r_{b1}\\varphi_1 - r_{b2}\\varphi_2$ for an internal one. The sliced "
    "potential-energy stiffness models external teeth only: an internal pair takes ISO "
    '6336-1 method B\'s mean stiffness (`source = "iso-6336"`, $z_{n2} = \\infty$) with '
    "the contact-line waveform, or the user's harmonics. Internal gears are supported in "
    "torsional models (no bearings, shafts, closed loops or carriers yet).\n"
)

_WHY = {
    "iso-6336": "ISO 6336-1 method B's mean $c_{\\gamma\\alpha} b$ with the ring as a rack "
    "($z_{n2} = \\infty$, the standard's rule for internal gears), and the contact-line "
    "waveform of $\\varepsilon_\\alpha$, $\\varepsilon_\\beta$ (for spur teeth the "
    "rectangular single/double contact wave)",
    "contact-line": "the user's mean stiffness with the contact-line waveform of "
    "$\\varepsilon_\\alpha$, $\\varepsilon_\\beta$",
    "harmonics": "the user's mean stiffness and harmonics",
}


def internal_section(model) -> str:
    """The internal meshes' subsection of section 1, or ``""`` when there is none."""
    topo = model.scene.topology
    meshes = [(i, me) for i, me in enumerate(topo.meshes) if me.pair.internal]
    if not meshes:
        return ""
    out: list[str] = []
    w = out.append
    w("### Internal meshes\n")
    w(
        "| mesh | ring $d$, $d_a$, $d_f$ (mm) | $a_w$ (mm) | $(d_2 - d_1)/2$ (mm) | "
        "$\\alpha_{wt}$ (deg) | trochoid margin (rad) | speed ratio |"
    )
    w("|---|---|---|---|---|---|---|")
    for _, me in meshes:
        p, r = me.pair.driver, me.pair.driven
        ratio = topo.signed_speed_ratios(me.driver)[me.driven]
        w(
            f"| {me.id} | {_num(2e3 * r.pitch_radius)}, {_num(2e3 * r.tip_radius)}, "
            f"{_num(2e3 * r.root_radius)} | {_num(me.pair.centre_distance * 1e3)} | "
            f"{_num((r.pitch_radius - p.pitch_radius) * 1e3)} | "
            f"{_num(math.degrees(me.pair.working_pressure_angle))} | "
            f"{_trochoid_margin(me.pair):.5f} | +{ratio.numerator}/{ratio.denominator} |"
        )
    w(
        "\nPinion and ring turn the same way. Each $\\theta_k$ is counted in its gear's own "
        "operating direction, so the incidence matrix $A$ (section 4) has the same form as "
        "for an external pair; in one frame for all gears, $\\theta_k = \\epsilon_k "
        "\\varphi_k$ with the turning senses $\\epsilon_k$, the deflection of an internal "
        "mesh is a difference of same-direction rotations:\n"
    )
    nd = getattr(model, "nondim", None)
    eq = getattr(nd, "equations", None)
    if eq is not None:
        sense = topo.senses()
        phi = {
            th: sense[g] * sp.Function(rf"\varphi_{{{g}}}")(eq.t)
            for th, g in zip(eq.theta, eq.gears, strict=True)
        }
        rows = [
            latex(eq.deflection[i].lhs) + " &= " + latex(eq.deflection[i].rhs.subs(phi)) + r" \\"
            for i, _ in meshes
        ]
        w(_math(r"\begin{aligned}", *rows, r"\end{aligned}"))
        w(
            "The mean mesh forces under the external torques, $F = W^{-1} C A I^{-1} T$ "
            "(section 4's $W$; positive: the driver's working flanks loaded), against the "
            "driver's torque over its base radius, $T_1/(r_{b1}\\cos\\beta_b)$, which they "
            "equal when the torques balance:\n"
        )
        C = sp.diag(*[sp.cos(b) for b in eq.beta_b])
        I_inv = sp.diag(*[1 / i for i in eq.inertia])
        load = C * eq.incidence * I_inv * sp.Matrix(eq.torque)
        force = np.linalg.solve(
            np.array(eq.compliance.subs(nd.values).evalf(17), dtype=float),
            np.array(load.subs(nd.values).evalf(17), dtype=float).ravel(),
        )
        for i, me in meshes:
            k = eq.gears.index(me.driver)
            by_torque = eq.torque[k] / (eq.base_radius[k] * sp.cos(eq.beta_b[i]))
            w(
                f"- {me.id}: $F$ = {_num(float(force[i]))} N; "
                f"$T_{{{me.driver}}}/(r_{{b,{me.driver}}}\\cos\\beta_b)$ = "
                f"{_num(nd.value(by_torque))} N."
            )
        w("")
    for _, me in meshes:
        w(
            f"Stiffness of {me.id}: `{me.stiffness.source}`, "
            + _WHY.get(me.stiffness.source, me.stiffness.source)
            + ". The sliced potential-energy method (`derive/mesh/pem.py`) models external "
            "teeth and their fillet foundation only, so it is not applied to a ring.\n"
        )
    return "\n".join(out)
