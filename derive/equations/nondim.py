"""Non-dimensionalisation of the reduced mesh equations.

Scales: the half backlash ``b_i`` of each mesh (``u_i = x_i / b_i``) and the natural
frequency of the reference mesh (the first), ``omega_n = sqrt(k_m,1 W_11)``, with
``tau = omega_n t``.  The damping follows from one damping ratio ``zeta`` in one of two
normalisations (the reference study does not say which it used):

* ``"mesh"`` (default): a viscous damper per mesh, set on the mesh's own equivalent mass
  ``1 / W_jj``: ``c_j = 2 zeta sqrt(k_m,j / W_jj)``;
* ``"modal"``: every mode of the mean-stiffness linear system has damping ratio ``zeta``:
  the damping acceleration is ``2 zeta (W K)^(1/2) x'`` with ``K = diag(k_m,j)``, i.e. the
  damper matrix ``C = 2 zeta W^-1 (W K)^(1/2)`` (full: it couples the meshes even where
  ``W_ij = 0``); ``c_j`` below is then its diagonal.

Dividing equation ``i`` of ``x'' + W F = C A I^-1 T + e''`` by ``b_i omega_n^2`` gives

    ``u_i'' + sum_j 2 xi_ij u_j' + sum_j kappa_ij(tau) g(u_j) = f_i + ebar_i''(tau)``

with

* ``kappa_ij(tau) = K_ij k_j(t) / k_m,j``,  ``K_ij = W_ij b_j k_m,j / (b_i omega_n^2)``,
* ``xi_ij = W_ij c_j b_j / (2 b_i omega_n)`` (``"mesh"``), or
  ``xi_ij = zeta [(W K)^(1/2)]_ij b_j / (b_i omega_n)`` (``"modal"``),
* ``f_i = (C A I^-1 T)_i / (b_i omega_n^2)``,  ``ebar_i = e_i / b_i``.

By construction ``K_11 = 1``, and ``xi_11 = zeta`` for ``"mesh"``; with ``"modal"`` a
single mesh gives ``xi_11 = zeta`` too.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import sympy as sp

from ..input.topology import Topology
from .torsion import Equations, derive_equations

__all__ = ["DAMPING_NORMALISATIONS", "NonDim", "nondimensionalise"]

DAMPING_NORMALISATIONS = ("mesh", "modal")
DAMPING_TEXT = {  # the audit page's words for each normalisation
    "mesh": "the damping coefficient of each mesh follows from one damping ratio $\\zeta$ on "
    'the mesh\'s own equivalent mass $1/W_{jj}$ (`damping_normalisation = "mesh"`)',
    "modal": 'the damping is modal (`damping_normalisation = "modal"`): every mode of the '
    "mean-stiffness linear system has damping ratio $\\zeta$, the damping acceleration is "
    "$2\\zeta (W K)^{1/2}\\dot x$; below, $c_j$ is the diagonal of its damper matrix "
    "$2\\zeta W^{-1}(WK)^{1/2}$",
}


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
    damping: str = "mesh"  # the normalisation (module docstring)

    def value(self, expr: sp.Expr) -> float:
        """Numeric value of a closed-form expression for this topology and scene."""
        return float(sp.sympify(expr).subs(self.values).evalf(17))

    def torque_symbol(self, gear: str) -> sp.Symbol:
        """The symbol of the external torque on ``gear`` (the reading of the loads)."""
        eq = self.equations
        return eq.torque[eq.gears.index(gear)]


def nondimensionalise(
    topology: Topology,
    damping_ratio: float = 0.0,
    equations: Equations | None = None,
    damping: str = "mesh",
) -> NonDim:
    """Closed-form scales and coefficients of ``topology`` (module docstring)."""
    eq = equations if equations is not None else derive_equations(topology)
    W = eq.compliance
    m = len(eq.meshes)
    zeta = sp.Symbol(r"\zeta", nonnegative=True)
    omega_n_expr = sp.sqrt(eq.mean_stiffness[0] * W[0, 0])
    b, km = eq.half_backlash, eq.mean_stiffness

    values: dict[sp.Symbol, float] = {zeta: float(damping_ratio)}
    for k, gear in enumerate(topology.gears):
        values[eq.inertia[k]] = gear.inertia
        values[eq.base_radius[k]] = gear.base_radius
        values[eq.torque[k]] = topology.torques.get(gear.id, 0.0)
    for i, mesh in enumerate(topology.meshes):
        values[eq.beta_b[i]] = mesh.pair.driver.base_helix_angle
        values[eq.half_backlash[i]] = mesh.half_backlash
        values[eq.mean_stiffness[i]] = mesh.stiffness.mean

    def simplify(expr):
        # Every factor is positive (masses, radii, stiffnesses, cos(beta_b) with
        # beta_b < 45 deg), so absolute values that sqrt() leaves behind can go.
        expr = sp.factor(sp.simplify(expr))
        return expr.replace(lambda e: isinstance(e, sp.Abs), lambda e: e.args[0])

    kappa = sp.ImmutableMatrix(
        m, m, lambda i, j: simplify(W[i, j] * b[j] * km[j] / (b[i] * omega_n_expr**2))
    )
    if damping == "mesh":
        damping_expr = tuple(2 * zeta * sp.sqrt(km[j] / W[j, j]) for j in range(m))
        xi = sp.ImmutableMatrix(
            m,
            m,
            lambda i, j: simplify(W[i, j] * damping_expr[j] * b[j] / (2 * b[i] * omega_n_expr)),
        )
    elif damping == "modal":
        root, damper = _modal(W, km, values)
        wn = float(omega_n_expr.subs(values))
        bv = [values[bb] for bb in b]
        damping_expr = tuple(2 * zeta * sp.Float(damper[j, j], 15) for j in range(m))
        xi = sp.ImmutableMatrix(
            m, m, lambda i, j: zeta * sp.Float(root[i, j] * bv[j] / (bv[i] * wn), 15)
        )
    else:
        raise ValueError(f"damping normalisation {damping!r}: not one of {DAMPING_NORMALISATIONS}")
    load = tuple(simplify(eq.load[i] / (b[i] * omega_n_expr**2)) for i in range(m))
    return NonDim(eq, zeta, omega_n_expr, damping_expr, kappa, xi, load, values, damping)


def _modal(W, km, values) -> tuple[np.ndarray, np.ndarray]:
    """``(W K)^(1/2)`` (1/s) and ``W^-1 (W K)^(1/2)`` (kg/s, the damper matrix over 2 zeta)
    for the numeric ``W`` and ``K = diag(k_m)``: ``W K`` is similar to the symmetric
    positive-definite ``K^(1/2) W K^(1/2)``, whose square root is taken by its eigenvectors."""
    w = np.array(W.subs(values).evalf(17), dtype=float)
    k = np.array([values[s] for s in km], dtype=float)
    half = np.sqrt(k)
    lam, vec = np.linalg.eigh(half[:, None] * w * half[None, :])
    root_sym = (vec * np.sqrt(lam)) @ vec.T
    root = root_sym * (half[None, :] / half[:, None])  # K^-1/2 (.) K^1/2
    return root, np.linalg.solve(w, root)
