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

With the dead-zone backlash the force law has kinks at ``|u| = 1``.  The vector field
stays continuous there, so the fundamental matrix needs no saltation jump, but an
integrator that steps over a kink loses its order.  ``FlowMap(system, locate=True)`` (the
default for dead-zone models) therefore integrates the plain flow and the variational
equations with SciPy's DOP853, stopping and restarting at every crossing; the ``"ad"``
route stays on CVODES, whose error control is all it has against the kinks.
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
    locate: bool | None = None  # None: locate crossings when the backlash is a dead zone
    _cache: dict = field(default_factory=dict, repr=False)

    def __post_init__(self):
        if self.locate is None:
            self.locate = self.system.backlash == "dead-zone"

    def _located(self, x0, duration, t0, p, with_phi: bool):
        """DOP853 on (x, Phi, int trace J), restarted at every contact-boundary crossing."""
        from scipy.integrate import solve_ivp

        from .simulate import _boundary_event

        sys_, n = self.system, self.system.n
        m = len(sys_.coordinates)
        p = sys_.p if p is None else p
        rhs, jac = sys_.module.rhs, sys_.module.jacobian

        def f(t, z):
            x = z[:n]
            J = jac(t, x, p)
            out = [rhs(t, x, p)]
            if with_phi:
                out.append((J @ z[n : n + n * n].reshape(n, n)).ravel())
            out.append([np.trace(J)])
            return np.concatenate(out)

        z = np.concatenate([x0, np.eye(n).ravel() if with_phi else [], [0.0]])
        t, t_end = t0, t0 + duration
        offset: dict[int, float] = {}
        edges = [(i, e) for i in range(m) for e in (1.0, -1.0)]
        for _ in range(100_000):
            events = [_boundary_event(i, e, offset.get(k, 0.0)) for k, (i, e) in enumerate(edges)]
            sol = solve_ivp(f, (t, t_end), z, method="DOP853", rtol=self.rtol, atol=self.atol,
                            events=events)  # fmt: skip
            if sol.status == -1:
                raise RuntimeError(f"DOP853 failed at tau = {t:.6g}: {sol.message}")
            z = sol.y[:, -1]
            if sol.status == 0:
                break
            t = float(sol.t[-1])
            offset = {k: np.copysign(1e-10, z[m + i]) for k, (i, e) in enumerate(edges)
                      if abs(z[i] - e) <= 1e-9}  # fmt: skip
        else:
            raise RuntimeError("too many contact-boundary crossings in one flow interval")
        xf = z[:n]
        Phi = z[n : n + n * n].reshape(n, n) if with_phi else None
        return xf, Phi, float(z[-1])

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
        if self.locate:
            return self._located(np.asarray(x0, float), duration, t0, p, False)[0]
        F = self._integrator("plain", duration)
        pp = np.concatenate([self.system.p if p is None else p, [t0]])
        return np.asarray(F(x0=np.asarray(x0, float), p=pp)["xf"]).ravel()

    def with_jacobian(self, x0, duration: float, t0: float = 0.0, p=None,
                      method: str | None = None, fd_step: float = 1e-5):  # fmt: skip
        """(end state, d end / d start, int trace J) over ``duration`` from ``x0``.

        ``method`` defaults to ``"variational"`` when crossings are located (dead zone),
        else ``"ad"``."""
        if method is None:
            method = "variational" if self.locate else "ad"
        if method not in MONODROMY_METHODS:
            raise ValueError(f"unknown monodromy method '{method}'; methods: "
                             f"{', '.join(MONODROMY_METHODS)}")  # fmt: skip
        x0 = np.asarray(x0, float)
        n = x0.size
        pp = np.concatenate([self.system.p if p is None else p, [t0]])
        if method == "ad":
            xf, M, q = self._integrator("ad", duration)(x0, pp)
            return np.asarray(xf).ravel(), np.asarray(M), float(q)
        if method == "variational" and self.locate:
            return self._located(x0, duration, t0, p, True)
        if method == "fd" and self.locate:
            xf, _, q = self._located(x0, duration, t0, p, False)
            M = np.empty((n, n))
            for j in range(n):
                e = np.zeros(n)
                e[j] = fd_step
                plus = self._located(x0 + e, duration, t0, p, False)[0]
                minus = self._located(x0 - e, duration, t0, p, False)[0]
                M[:, j] = (plus - minus) / (2 * fd_step)
            return xf, M, q
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
