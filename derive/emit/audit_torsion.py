"""The audit page's sections 2-6 for a torsional model: Newton's second law for each gear,
the mesh deflections and forces, the elimination of the rigid-body rotation (the compliance
``W = C A I^-1 A^T C``), the reduced equations and the scales, written from the same SymPy
objects as the code (``derive/equations/torsion.py``, ``derive/equations/nondim.py``)."""

from __future__ import annotations

import sympy as sp

from ..equations.nondim import DAMPING_TEXT
from ..model import Model
from .markdown import latex
from .markdown import math_block as _math
from .markdown import number as _num

__all__ = ["torsional_sections"]


def torsional_sections(model: Model) -> str:
    """Sections 2-6 of ``docs/derivation/<name>.md`` for a torsional model."""
    out: list[str] = []
    w = out.append
    scene, nd = model.scene, model.nondim
    eq = nd.equations
    w("## 2. Newton's second law for each gear\n")
    w(
        "Rotations $\\theta_k$ are positive in each gear's operating direction; "
        "$F$ is the mesh force along the normal line of action, whose transverse component "
        "$F\\cos\\beta_b$ acts at the base radius.\n"
    )
    w(
        _math(
            r"\begin{aligned}",
            *[latex(e.lhs) + " &= " + latex(e.rhs) + r" \\" for e in eq.newton],
            r"\end{aligned}",
        )
    )

    w("## 3. Mesh deflections and mesh forces\n")
    w(
        "Deflection along the normal line of action, with the composite transmission error "
        "$e$ (positive for excess material), and the mesh force with backlash function $g$ "
        "of unit half backlash:\n"
    )
    w(
        _math(
            r"\begin{aligned}",
            *[latex(e.lhs) + " &= " + latex(e.rhs) + r" \\" for e in eq.deflection + eq.force_law],
            r"\end{aligned}",
        )
    )

    w("## 4. Eliminating the rigid-body rotation\n")
    w(
        "Differentiating each deflection twice and substituting $\\ddot\\theta$ from "
        "section 2 (SymPy, expanded):\n"
    )
    w(
        _math(
            r"\begin{aligned}",
            *[latex(e.lhs) + " &= " + latex(e.rhs) + r" \\" for e in eq.substituted],
            r"\end{aligned}",
        )
    )
    w(
        "No $\\theta$ is left: the rigid-body rotation has dropped out (checked in the "
        "derivation). The compliance $W_{ij} = -\\partial\\ddot x_i/\\partial F_j$ equals "
        "$C A I^{-1} A^T C$ with the incidence matrix $A$ (base radii with sign) and "
        "$C = \\mathrm{diag}(\\cos\\beta_b)$:\n"
    )
    w(_math("A = " + latex(eq.incidence) + r",\qquad W = " + latex(eq.compliance)))
    Wn = eq.compliance.subs(nd.values).evalf(10)
    w(
        _math(
            "W = "
            + latex(sp.Matrix(Wn).applyfunc(lambda v: sp.Float(v, 6)))
            + r"\ \mathrm{kg^{-1}}"
        )
    )

    w("## 5. Reduced equations\n")
    w(
        _math(
            r"\begin{aligned}",
            *[latex(e.lhs) + " &= " + latex(e.rhs) + r" \\" for e in eq.reduced],
            r"\end{aligned}",
        )
    )

    w("## 6. Scales\n")
    w(
        "Each mesh is scaled by its half backlash, $u_i = x_i/b_i$; time by the natural "
        "frequency of the reference mesh (the first), $\\tau = \\omega_n t$; "
        + DAMPING_TEXT[nd.damping]
        + ":\n"
    )
    w(
        _math(
            r"\begin{aligned}",
            r"\omega_n &= "
            + latex(nd.omega_n_expr)
            + " = "
            + _num(model.scales["omega_n_rad_per_s"], 8)
            + r"\ \mathrm{rad/s} \\",
            *[
                f"{latex(eq.damping[j])} &= {latex(nd.damping_expr[j])} = "
                f"{_num(nd.value(nd.damping_expr[j]))}" + r"\ \mathrm{N\,s/m} \\"
                for j in range(len(eq.meshes))
            ],
            r"\end{aligned}",
        )
    )
    w(
        f"with $\\zeta = {_num(scene.damping_ratio)}$. "
        f"One unit of $\\tau$ is {_num(model.scales['time_unit_s'])} s.\n"
    )
    return "\n".join(out)
