"""The flow map over a forcing interval and its derivative, three ways.

``FlowMap(system)`` integrates ``x' = F(tau, x, p)`` from ``t0`` over ``duration`` with
CVODES.  The derivative of the end state with respect to the initial state (over one
period of a periodic orbit: the monodromy matrix) comes from

* ``"ad"``: CasADi's forward sensitivities of the integrator (automatic differentiation
  through the integration);
* ``"variational"``: the variational equations ``Phi' = J(tau, x) Phi`` integrated with the
  state, ``J`` the generated Jacobian;
* ``"fd"``: central finite differences of the flow map.

Every route also integrates ``trace J`` along the trajectory, for Liouville's formula
``det Phi = exp(int trace J dtau)``.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .system import System

__all__ = ["FlowMap", "MONODROMY_METHODS"]

MONODROMY_METHODS = ("ad", "variational", "fd")


@dataclass(eq=False)
class FlowMap:
    """Integrator of one system (one parameter vector may be swapped in per call)."""

    system: System
    rtol: float = 1e-11
    atol: float = 1e-13
    _cache: dict = field(default_factory=dict, repr=False)

    def _integrator(self, kind: str, duration: float):
        key = (kind, round(duration, 14))
        if key in self._cache:
            return self._cache[key]
        import casadi as ca

        f, jac = self.system.casadi
        n, P = self.system.n, self.system.p.size
        tau, x = ca.SX.sym("tau"), ca.SX.sym("x", n)
        p, shift = ca.SX.sym("p", P), ca.SX.sym("shift")
        t = tau + shift  # integrate from 0 with the forcing shifted to start at t0
        J = jac(t, x, p)
        trace = ca.trace(J)
        if kind == "variational":
            Phi = ca.SX.sym("Phi", n, n)
            states = ca.vertcat(x, ca.vec(Phi))
            ode = ca.vertcat(f(t, x, p), ca.vec(ca.mtimes(J, Phi)))
        else:
            states, ode = x, f(t, x, p)
        dae = {"x": states, "p": ca.vertcat(p, shift), "t": tau, "ode": ode, "quad": trace}
        opts = {"reltol": self.rtol, "abstol": self.atol, "max_num_steps": 2_000_000,
                "fsens_err_con": True}  # fmt: skip
        F = ca.integrator(f"flow_{kind}", "cvodes", dae, 0.0, duration, opts)
        if kind == "ad":
            x0 = ca.MX.sym("x0", n)
            pp = ca.MX.sym("pp", P + 1)
            out = F(x0=x0, p=pp)
            xf = out["xf"]
            F = ca.Function("flow_ad", [x0, pp], [xf, ca.jacobian(xf, x0), out["qf"]])
        self._cache[key] = F
        return F

    def __call__(self, x0, duration: float, t0: float = 0.0, p=None) -> np.ndarray:
        """End state after ``duration`` from ``x0`` at ``t0``."""
        F = self._integrator("plain", duration)
        pp = np.concatenate([self.system.p if p is None else p, [t0]])
        return np.asarray(F(x0=np.asarray(x0, float), p=pp)["xf"]).ravel()

    def with_jacobian(self, x0, duration: float, t0: float = 0.0, p=None,
                      method: str = "ad", fd_step: float = 1e-5):  # fmt: skip
        """(end state, d end / d start, int trace J) over ``duration`` from ``x0``."""
        if method not in MONODROMY_METHODS:
            raise ValueError(f"unknown monodromy method '{method}'; methods: "
                             f"{', '.join(MONODROMY_METHODS)}")  # fmt: skip
        x0 = np.asarray(x0, float)
        n = x0.size
        pp = np.concatenate([self.system.p if p is None else p, [t0]])
        if method == "ad":
            xf, M, q = self._integrator("ad", duration)(x0, pp)
            return np.asarray(xf).ravel(), np.asarray(M), float(q)
        if method == "variational":
            z0 = np.concatenate([x0, np.eye(n).ravel(order="F")])
            out = self._integrator("variational", duration)(x0=z0, p=pp)
            z = np.asarray(out["xf"]).ravel()
            return z[:n], z[n:].reshape((n, n), order="F"), float(out["qf"])
        F = self._integrator("plain", duration)
        out = F(x0=x0, p=pp)
        xf, q = np.asarray(out["xf"]).ravel(), float(out["qf"])
        # Central differences: truncation ~ h^2, integration noise ~ rtol / h.
        M = np.empty((n, n))
        for j in range(n):
            e = np.zeros(n)
            e[j] = fd_step
            plus = np.asarray(F(x0=x0 + e, p=pp)["xf"]).ravel()
            minus = np.asarray(F(x0=x0 - e, p=pp)["xf"]).ravel()
            M[:, j] = (plus - minus) / (2 * fd_step)
        return xf, M, q
