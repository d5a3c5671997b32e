"""Non-dimensionalisation of the reduced mesh equations.

Scales: the half backlash ``b_i`` of each mesh (``u_i = x_i / b_i``) and the natural
frequency of the reference mesh (the first), ``omega_n = sqrt(k_m,1 W_11)``, with
``tau = omega_n t``.  Mesh damping is set from one damping ratio ``zeta`` per mesh on its
own equivalent mass ``1 / W_jj``: ``c_j = 2 zeta sqrt(k_m,j / W_jj)``.

Dividing equation ``i`` of ``x'' + W F = C A I^-1 T + e''`` by ``b_i omega_n^2`` gives

    ``u_i'' + sum_j 2 xi_ij u_j' + sum_j kappa_ij(tau) g(u_j) = f_i + ebar_i''(tau)``

with

* ``kappa_ij(tau) = K_ij k_j(t) / k_m,j``,  ``K_ij = W_ij b_j k_m,j / (b_i omega_n^2)``,
* ``xi_ij = W_ij c_j b_j / (2 b_i omega_n)``,
* ``f_i = (C A I^-1 T)_i / (b_i omega_n^2)``,  ``ebar_i = e_i / b_i``.

By construction ``K_11 = 1`` and ``xi_11 = zeta``.
"""

from __future__ import annotations

from dataclasses import dataclass

import sympy as sp

from .equations import Equations, derive_equations
from .topology import Topology

__all__ = ["NonDim", "nondimensionalise"]


@dataclass(frozen=True)
class NonDim:
    """Scales and closed-form non-dimensional coefficients, with their numeric values."""

    equations: Equations
    zeta: sp.Symbol
    omega_n_expr: sp.Expr
    damping_expr: tuple[sp.Expr, ...]
    kappa: sp.ImmutableMatrix
    xi: sp.ImmutableMatrix
    load: tuple[sp.Expr, ...]
    values: dict[sp.Symbol, float]

    def value(self, expr: sp.Expr) -> float:
        """Numeric value of a closed-form expression for this topology and scene."""
        return float(sp.sympify(expr).subs(self.values).evalf(17))


def nondimensionalise(
    topology: Topology, damping_ratio: float = 0.0, equations: Equations | None = None
) -> NonDim:
    """Closed-form scales and coefficients of ``topology`` (module docstring)."""
    eq = equations if equations is not None else derive_equations(topology)
    W = eq.compliance
    m = len(eq.meshes)
    zeta = sp.Symbol(r"\zeta", nonnegative=True)
    omega_n_expr = sp.sqrt(eq.mean_stiffness[0] * W[0, 0])
    damping = tuple(2 * zeta * sp.sqrt(eq.mean_stiffness[j] / W[j, j]) for j in range(m))
    b, km = eq.half_backlash, eq.mean_stiffness

    def simplify(expr):
        # Every factor is positive (masses, radii, stiffnesses, cos(beta_b) with
        # beta_b < 45 deg), so absolute values that sqrt() leaves behind can go.
        expr = sp.factor(sp.simplify(expr))
        return expr.replace(lambda e: isinstance(e, sp.Abs), lambda e: e.args[0])

    kappa = sp.ImmutableMatrix(
        m, m, lambda i, j: simplify(W[i, j] * b[j] * km[j] / (b[i] * omega_n_expr**2))
    )
    xi = sp.ImmutableMatrix(
        m, m, lambda i, j: simplify(W[i, j] * damping[j] * b[j] / (2 * b[i] * omega_n_expr))
    )
    load = tuple(simplify(eq.load[i] / (b[i] * omega_n_expr**2)) for i in range(m))

    values: dict[sp.Symbol, float] = {zeta: float(damping_ratio)}
    for k, gear in enumerate(topology.gears):
        values[eq.inertia[k]] = gear.inertia
        values[eq.base_radius[k]] = gear.base_radius
        values[eq.torque[k]] = topology.torques.get(gear.id, 0.0)
    for i, mesh in enumerate(topology.meshes):
        values[eq.beta_b[i]] = mesh.pair.driver.base_helix_angle
        values[eq.half_backlash[i]] = mesh.half_backlash
        values[eq.mean_stiffness[i]] = mesh.stiffness.mean
    return NonDim(eq, zeta, omega_n_expr, damping, kappa, xi, load, values)
