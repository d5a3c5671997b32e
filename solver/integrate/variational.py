"""The variational equations, built in one place for every caller.

Along a solution of ``x' = F(tau, x, p)`` a set of tangent vectors ``W`` (n, k) evolves
by ``W' = J(tau, x, p) W`` with ``J = dF/dx`` the generated Jacobian; with ``W(0) = I``
it is the fundamental matrix (over one period of a periodic orbit, the monodromy
matrix), with one column it is the tangent vector of Benettin's Lyapunov estimate.  The
integral of ``trace J`` rides along for Liouville's formula ``det W = exp(int trace J)``.

* :func:`casadi_dae` -- the CasADi problem, integrated from 0 with the forcing shifted to
  start at ``t0`` (the shift is the last parameter), for CVODES;
* :func:`numpy_rhs` -- the same right-hand side on the generated NumPy functions, for the
  SciPy event loop (``events.py``) that locates switching surfaces.

The compiled Lyapunov run uses the C variational right-hand side that ``derive/emit/c.py``
prints from the same SymPy Jacobian.
"""

from __future__ import annotations

import numpy as np

__all__ = ["casadi_dae", "numpy_rhs", "pack", "unpack"]


def casadi_dae(system, tangents: int = 0, trace: bool = False) -> dict:
    """CasADi DAE dictionary of the state with ``tangents`` tangent columns.

    States ``vertcat(x, vec(W))`` (``vec`` column-major), parameters ``vertcat(p, shift)``
    with forcing time ``tau + shift``; with ``trace`` the quadrature ``trace J``.
    """
    import casadi as ca

    f, jac = system.casadi
    n, P = system.n, system.p.size
    tau, x = ca.SX.sym("tau"), ca.SX.sym("x", n)
    p, shift = ca.SX.sym("p", P), ca.SX.sym("shift")
    t = tau + shift
    J = jac(t, x, p)
    if tangents:
        W = ca.SX.sym("W", n, tangents)
        states = ca.vertcat(x, ca.vec(W))
        ode = ca.vertcat(f(t, x, p), ca.vec(ca.mtimes(J, W)))
    else:
        states, ode = x, f(t, x, p)
    dae = {"x": states, "p": ca.vertcat(p, shift), "t": tau, "ode": ode}
    if trace:
        dae["quad"] = ca.trace(J)
    return dae


def numpy_rhs(module, p, n: int, tangents: int = 0):
    """``z' = (F, J W, trace J)`` for ``z = pack(x, W, q)`` on the generated NumPy code."""
    rhs, jac = module.rhs, module.jacobian

    def f(t, z):
        x = z[:n]
        J = jac(t, x, p)
        out = [rhs(t, x, p)]
        if tangents:
            out.append((J @ z[n : n + n * tangents].reshape(n, tangents)).ravel())
        out.append([np.trace(J)])
        return np.concatenate(out)

    return f


def pack(x, W=None, q: float = 0.0) -> np.ndarray:
    """The augmented state of :func:`numpy_rhs` (``W`` row-major)."""
    parts = [np.asarray(x, float)]
    if W is not None:
        parts.append(np.asarray(W, float).ravel())
    return np.concatenate([*parts, [q]])


def unpack(z, n: int, tangents: int = 0):
    """``(x, W or None, q)`` from an augmented state."""
    W = z[n : n + n * tangents].reshape(n, tangents) if tangents else None
    return z[:n], W, float(z[-1])
