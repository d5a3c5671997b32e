"""Newton's second law per gear, mesh coordinates, and the reduced mesh equations.

For ``n`` gears joined by ``m = n - 1`` meshes (a tree), with ``theta_k`` the rotation of
gear ``k`` counted positive in its operating direction:

* Newton:      ``I_k theta_k'' = T_k - sum_i cos(beta_b,i) A_ik F_i``
* deflection:  ``x_i = cos(beta_b,i) sum_k A_ik theta_k + s_i e_i(t)``, along the normal
  line of action, with ``A_ik = +s_i r_b,k`` for the driver and ``-s_i r_b,k`` for the driven
  gear of mesh ``i`` (0 otherwise), ``s_i = +1`` for a coordinate measured forward (driver
  flank loaded = positive) and ``-1`` for one measured the other way (``derive.readings``),
  and ``e_i`` the composite transmission error (positive = excess material, which presses
  the flanks together);
  the same for an internal mesh (a pinion driving a ring): pinion and ring turn the same
  way, but each ``theta_k`` is counted in its own gear's operating direction, so in one
  frame for all gears (``theta_k = epsilon_k phi_k``, ``Topology.senses``) the deflection
  is ``r_b1 phi_1 + r_b2 phi_2`` for an external pair and ``r_b1 phi_1 - r_b2 phi_2`` for
  an internal one (the audit prints both forms);
* mesh force:  ``F_i = k_i(t) b_i g(x_i / b_i) + c_i x_i'`` along the normal line of action;
  its transverse component ``F_i cos(beta_b,i)`` acts at the base radius.

Differentiating ``x_i`` twice and substituting ``theta''`` from Newton's law gives, with
``C = diag(cos beta_b)`` and ``I = diag(I_k)``,

    ``x'' + W F = C A I^-1 T + S e''``,   ``W = C A I^-1 A^T C``  (m x m, symmetric),

in which no ``theta`` remains: the rigid-body rotation has dropped out.  ``W_ij`` is the
inverse equivalent mass coupling meshes ``i`` and ``j``; it is non-zero only when they
share a gear, and its sign is ``s_i s_j`` times that of the forward-measured pair.  ``S =
diag(s_i)``.  The derivation here is carried out on SymPy objects and checked term by
term; ``I`` is diagonal, so no matrix is inverted symbolically.
"""

from __future__ import annotations

from dataclasses import dataclass

import sympy as sp

from ..input.topology import Topology

__all__ = ["Equations", "derive_equations"]


@dataclass(frozen=True)
class Equations:
    """The dimensional derivation of one topology, step by step (SymPy objects)."""

    t: sp.Symbol
    gears: tuple[str, ...]
    meshes: tuple[str, ...]
    theta: tuple[sp.Expr, ...]
    inertia: tuple[sp.Symbol, ...]
    torque: tuple[sp.Symbol, ...]
    base_radius: tuple[sp.Symbol, ...]
    beta_b: tuple[sp.Symbol, ...]
    half_backlash: tuple[sp.Symbol, ...]
    mean_stiffness: tuple[sp.Symbol, ...]
    damping: tuple[sp.Symbol, ...]
    stiffness: tuple[sp.Expr, ...]
    te: tuple[sp.Expr, ...]
    force: tuple[sp.Symbol, ...]
    x: tuple[sp.Expr, ...]
    orientation: tuple[int, ...]  # s_i: +1 forward, -1 reversed
    g: sp.FunctionClass
    incidence: sp.ImmutableMatrix
    newton: tuple[sp.Eq, ...]
    deflection: tuple[sp.Eq, ...]
    force_law: tuple[sp.Eq, ...]
    substituted: tuple[sp.Eq, ...]
    compliance: sp.ImmutableMatrix
    load: tuple[sp.Expr, ...]
    reduced: tuple[sp.Eq, ...]


def derive_equations(topology: Topology) -> Equations:
    """Derive the reduced mesh equations of ``topology`` (see module docstring)."""
    t = sp.Symbol("t", real=True)
    gears = tuple(g.id for g in topology.gears)
    meshes = tuple(m.id for m in topology.meshes)
    theta = tuple(sp.Function(rf"\theta_{{{g}}}")(t) for g in gears)
    inertia = tuple(sp.Symbol(f"I_{{{g}}}", positive=True) for g in gears)
    torque = tuple(sp.Symbol(f"T_{{{g}}}", real=True) for g in gears)
    radius = tuple(sp.Symbol(f"r_{{b,{g}}}", positive=True) for g in gears)
    beta_b = tuple(sp.Symbol(rf"\beta_{{b,{m}}}", nonnegative=True) for m in meshes)
    b = tuple(sp.Symbol(f"b_{{{m}}}", positive=True) for m in meshes)
    km = tuple(sp.Symbol(f"k_{{m,{m}}}", positive=True) for m in meshes)
    c = tuple(sp.Symbol(f"c_{{{m}}}", nonnegative=True) for m in meshes)
    k = tuple(sp.Function(f"k_{{{m}}}")(t) for m in meshes)
    e = tuple(sp.Function(f"e_{{{m}}}")(t) for m in meshes)
    F = tuple(sp.Symbol(f"F_{{{m}}}", real=True) for m in meshes)
    x = tuple(sp.Function(f"x_{{{m}}}")(t) for m in meshes)
    g = sp.Function("g")

    col = {gid: j for j, gid in enumerate(gears)}
    s = tuple(int(mesh.orientation) for mesh in topology.meshes)
    A = sp.zeros(len(meshes), len(gears))
    for i, mesh in enumerate(topology.meshes):
        A[i, col[mesh.driver]] = s[i] * radius[col[mesh.driver]]
        A[i, col[mesh.driven]] = -s[i] * radius[col[mesh.driven]]
    A = sp.ImmutableMatrix(A)
    cb = [sp.cos(bb) for bb in beta_b]

    newton = tuple(
        sp.Eq(
            inertia[kk] * theta[kk].diff(t, 2),
            torque[kk] - sum(cb[i] * A[i, kk] * F[i] for i in range(len(meshes))),
        )
        for kk in range(len(gears))
    )
    kinematic = [
        cb[i] * sum(A[i, kk] * theta[kk] for kk in range(len(gears))) for i in range(len(meshes))
    ]
    deflection = tuple(sp.Eq(x[i], kinematic[i] + s[i] * e[i]) for i in range(len(meshes)))
    force_law = tuple(
        sp.Eq(F[i], k[i] * b[i] * g(x[i] / b[i]) + c[i] * x[i].diff(t)) for i in range(len(meshes))
    )

    # x_i'' with theta'' from Newton's law.
    accel = {
        theta[kk].diff(t, 2): sp.solve(newton[kk], theta[kk].diff(t, 2))[0]
        for kk in range(len(gears))
    }
    substituted = tuple(
        sp.Eq(x[i].diff(t, 2), sp.expand(deflection[i].rhs.diff(t, 2).subs(accel)))
        for i in range(len(meshes))
    )

    # Read the compliance W_ij = -d(x_i'')/dF_j and the load off the substituted form,
    # then check them against the closed form C A I^-1 A^T C and that nothing is left.
    W = sp.ImmutableMatrix(len(meshes), len(meshes), lambda i, j: -substituted[i].rhs.diff(F[j]))
    Iinv = sp.diag(*[1 / ii for ii in inertia])
    C = sp.diag(*cb)
    W_closed = C * A * Iinv * A.T * C
    load_closed = C * A * Iinv * sp.Matrix(torque)
    load = []
    for i in range(len(meshes)):
        rest = substituted[i].rhs + sum(W[i, j] * F[j] for j in range(len(meshes)))
        rest = sp.expand(rest - s[i] * e[i].diff(t, 2))
        if sp.expand(W[i, :] - W_closed[i, :]) != sp.zeros(1, len(meshes)):
            raise AssertionError(f"compliance row {i} does not match C A I^-1 A^T C")
        if sp.expand(rest - load_closed[i]) != 0 or rest.has(*theta):
            raise AssertionError(f"mesh {meshes[i]}: the rigid-body mode did not drop out")
        load.append(rest)

    reduced = tuple(
        sp.Eq(
            x[i].diff(t, 2) + sum(W[i, j] * F[j] for j in range(len(meshes))),
            load[i] + s[i] * e[i].diff(t, 2),
        )
        for i in range(len(meshes))
    )
    return Equations(
        t=t,
        gears=gears,
        meshes=meshes,
        theta=theta,
        inertia=inertia,
        torque=torque,
        base_radius=radius,
        beta_b=beta_b,
        half_backlash=b,
        mean_stiffness=km,
        damping=c,
        stiffness=k,
        te=e,
        force=F,
        x=x,
        orientation=s,
        g=g,
        incidence=A,
        newton=newton,
        deflection=deflection,
        force_law=force_law,
        substituted=substituted,
        compliance=sp.ImmutableMatrix(W),
        load=tuple(load),
        reduced=reduced,
    )
