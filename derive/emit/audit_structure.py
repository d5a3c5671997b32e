"""The audit page's sections 2-6 for a model beyond torsion (``derive/equations/structure.py``):
bodies and supports, the mesh geometry, the coordinates ``eta = R q``, the compliance
``W = R M^-1 R^T`` and the scales, written from the same SymPy objects as the code."""

from __future__ import annotations

import math

import sympy as sp

from .markdown import math_block as _math
from .markdown import number as _num

__all__ = ["structure_sections"]


def structure_sections(model) -> str:
    """Sections 2-6 of ``docs/derivation/<name>.md`` for a model with bearings or shafts."""
    st, topo = model.structure, model.scene.topology
    out: list[str] = []
    w = out.append
    w("## 2. Bodies, supports and coordinates\n")
    w(
        f"Degrees of freedom: `{st.dofs}`. Each gear turns ($\\theta_k$, positive in its "
        "operating direction)"
        + (
            " and moves across and along its axis on its bearing and tilts about x and y"
            if "tx" in {c.kind for c in st.coordinates}
            else " and moves across and along its axis on its bearing"
            if "z" in {c.kind for c in st.coordinates}
            else " and moves across its axis on its bearing"
            if "x" in {c.kind for c in st.coordinates}
            else ""
        )
        + "; $z$ is along the axes, the first mesh's driver turns counter-clockwise seen "
        "from $+z$. Masses: a cylinder of the pitch radius with the bore removed, "
        "$m = \\rho\\pi b_w (r^2 - r_{bore}^2)$, plus any attached mass"
        + (
            "; diametral inertia $J = m(3(r^2 + r_{bore}^2) + b_w^2)/12$ plus half the "
            "attached inertia: "
            + ", ".join(f"$J_{{{g.id}}}$ = {_num(g.diametral_inertia)} kg m²" for g in topo.gears)
            + "; tilting bearings: "
            + ", ".join(
                f"{g} {_num(b.tilt)} N m/rad, {_num(b.tilt_damping)} N m s/rad"
                for g, b in topo.bearings.items()
            )
            if "tx" in {c.kind for c in st.coordinates}
            else ""
        )
        + ".\n"
    )
    w(
        "| gear | turning sense | $m$ (kg) | $I$ (kg m²) | radial bearing (N/m, N s/m) | "
        "axial bearing (N/m, N s/m) |"
    )
    w("|---|---|---|---|---|---|")
    senses = topo.senses()
    for g in topo.gears:
        b = topo.bearings.get(g.id)
        radial = f"{_num(b.radial)}, {_num(b.radial_damping)}" if b else "none"
        if b and b.transverse("y")[2]:
            ky, cy, _ = b.transverse("y")
            radial = f"x: {radial}; y: {_num(ky)}, {_num(cy)}"
        axial = f"{_num(b.axial)}, {_num(b.axial_damping)}" if b else "none"
        sense = "counter-clockwise" if senses[g.id] > 0 else "clockwise"
        w(f"| {g.id} | {sense} | {_num(g.mass)} | {_num(g.inertia)} | {radial} | {axial} |")
    for s in topo.shafts:
        w(
            f"\nShaft `{s.id}` joins {s.gears[0]} and {s.gears[1]}: "
            f"$k = {_num(s.stiffness)}$ N m/rad, $c = {_num(s.damping)}$ N m s/rad."
        )
    w("")
    w("## 3. Mesh geometry and deflections\n")
    w(
        "The driver's centre lies at the angle $\\phi$ round the driven gear's; the "
        "transverse line of action (the force on the driven gear) is at "
        "$\\psi = \\phi + \\epsilon_{driven}(\\pi/2 + \\alpha_{wt})$; the normal line of "
        "action adds $\\sigma\\sin\\beta_b$ along $z$ with "
        "$\\sigma = \\mathrm{sign}(\\beta_{driver})\\,\\epsilon_{driver}$. The drive flank's "
        "line serves the back flank too (its radial component keeps the drive flank's "
        "sign). The contact is lumped at the pitch point in the face's centre plane; with "
        "tilting, a tilt moves it along $z$, so the axial force tilts the gears.\n"
    )
    w(
        "| mesh | $\\phi$ (deg) | $\\alpha_{wt}$ (deg) | $\\psi$ (deg) | $\\sigma$ | "
        "$\\beta_b$ (deg) | orientation $s$ |"
    )
    w("|---|---|---|---|---|---|---|")
    for me in topo.meshes:
        a = st.angles[me.id]
        w(
            f"| {me.id} | {_num(math.degrees(me.driver_position))} | "
            f"{_num(math.degrees(me.pair.working_pressure_angle))} | "
            f"{_num(math.degrees(st.value(a['psi'])))} | {a['sigma']:+d} | "
            f"{_num(math.degrees(st.value(a['beta_b'])))} | {me.orientation:+d} |"
        )
    w(
        "\nEach coordinate of $\\eta$ is a row of $R$ applied to "
        "$q = (" + ", ".join(sp.latex(s) for s in st.physical) + ")$ (a mesh's row adds "
        "$s\\,e(t)$, its transmission error):\n"
    )
    rows = []
    for i, c in enumerate(st.coordinates):
        expr = sum(st.incidence[i, k] * q for k, q in enumerate(st.physical))
        rows.append(f"\\eta_{{{c.name}}} &= {sp.latex(expr)} \\\\")
    w(_math(r"\begin{aligned}", *rows, r"\end{aligned}"))
    w("## 4. Newton's law and the compliance\n")
    w(
        "$M q'' = T - R^T(K g(\\eta) + C\\eta')$ with $M = \\mathrm{diag}("
        + ", ".join(sp.latex(m) for m in st.mass)
        + ")$ and the springs and dampers along $\\eta$: meshes (time-varying, with "
        "backlash), shafts and bearings. Then $\\eta'' + W(K g(\\eta) + C\\eta') = "
        "R M^{-1} T + S\\ddot e$ with $W = R M^{-1} R^T$; the rigid-body rotation "
        "(the null space of $R$) drops out. Numerically:\n"
    )
    Wn = sp.Matrix(st.compliance.subs(st.values).evalf(10)).applyfunc(lambda v: sp.Float(v, 4))
    w(_math("W = " + sp.latex(Wn) + r"\ \mathrm{(SI)}"))
    w("## 5. Springs and dampers along the coordinates\n")
    w("| coordinate | kind | of | stiffness | damping | scale |")
    w("|---|---|---|---|---|---|")
    for c, d in zip(st.coordinates, st.damping_expr, strict=True):
        w(
            f"| {c.name} | {c.kind} | {c.owner} | ${sp.latex(c.stiffness)}$ = "
            f"{_num(st.value(c.stiffness))} | ${sp.latex(d)}$ = {_num(st.value(d))} | "
            f"${sp.latex(c.scale)}$ = {_num(st.value(c.scale))} |"
        )
    w("")
    w("## 6. Scales\n")
    w(
        "Meshes are scaled by their half backlash, translations by the reference mesh's, "
        "a shaft's twist by $b_1/r_{b,a}$; time by the *torsional* natural frequency of the "
        "reference mesh, $\\omega_n^2 = k_{m,1}W^t_{11}$ with $W^t$ the rotations' part of "
        "$W$ (the torsional model's time scale); a mesh damper is "
        "$c_j = 2\\zeta\\sqrt{k_{m,j}/W^t_{jj}}$:\n"
    )
    w(
        _math(
            r"\omega_n = "
            + sp.latex(st.omega_n_expr)
            + " = "
            + _num(model.scales["omega_n_rad_per_s"], 8)
            + r"\ \mathrm{rad/s}"
        )
    )
    w(
        f"with $\\zeta = {_num(model.scene.damping_ratio)}$. "
        f"One unit of $\\tau$ is {_num(model.scales['time_unit_s'])} s.\n"
    )
    return "\n".join(out)
