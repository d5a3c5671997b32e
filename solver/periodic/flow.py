"""The flow map over a forcing interval and its derivative, three ways; the stroboscopic map.

``FlowMap(system)`` integrates ``x' = F(tau, x, p)`` from ``t0`` over ``duration`` with
CVODES; the parameter vector ``p`` may be swapped in per call, so one flow map serves a
whole continuation.  The derivative of the end state with respect to the initial state
(over one period of a periodic orbit: the monodromy matrix) comes from

* ``"ad"``: CasADi's forward sensitivities of the integrator (automatic differentiation
  through the integration);
* ``"variational"``: the variational equations ``Phi' = J(tau, x) Phi`` integrated with the
  state (``integrate/variational.py``), ``J`` the generated Jacobian;
* ``"fd"``: central finite differences of the flow map.

Every route also integrates ``trace J`` along the trajectory, for Liouville's formula
``det Phi = exp(int trace J dtau)``.

A piecewise model (the exact dead zone) has kinks on the switching surfaces of its
contract.  The vector field stays continuous there, so the fundamental matrix needs no
saltation jump, but an integrator that steps over a kink loses its order.
``FlowMap(system, locate=True)`` (the default for piecewise models) therefore integrates
the plain flow and the variational equations with SciPy's DOP853 through the one event
loop (``integrate/events.py``), stopping and restarting at every crossing; the ``"ad"``
route stays on CVODES, whose error control is all it has against the kinks.  A model whose
kinks are not on its coordinates (a planetary set's or a closed-loop train's meshes: the
contract's ``switching_rows``, no surface to stop at) takes the compiled engine's DOP853
instead over whole forcing periods, with its variational monodromy, as the orbit check
does (``analysis/orbit_check.py``): the event loop would only have integrated it in
Python.  Its dampers are linear, so ``trace J`` is constant and its integral is the
duration times ``trace J`` at the start (checked at another state and time; NaN, no
Liouville check, where they differ).  Only whole periods take this route: a multiple
shooting segment shorter than a period still takes the event loop, correct but slow.

``StroboscopicMap(system, n)`` is the period map ``x -> phi_{nT}(x; t0)`` as an object of
its own: fixed points are period-n orbits, its Jacobian is the monodromy matrix.
"""

from __future__ import annotations

from collections import OrderedDict
from dataclasses import dataclass, field, replace

import numpy as np

from ..integrate._quiet import quiet
from ..integrate.events import integrate_located
from ..integrate.variational import casadi_dae, numpy_rhs, pack, unpack
from ..system import System

__all__ = ["MONODROMY_METHODS", "FlowMap", "StroboscopicMap", "monodromy_agreement"]

MONODROMY_METHODS = ("ad", "variational", "fd")
_MOST_STEPS_A_PERIOD = 100_000  # of the compiled route (unlocated kinks); a few hundred is usual
_CACHED_INTEGRATORS = 32  # durations kept per flow map (a continuation in omega makes many)


@dataclass(eq=False)
class FlowMap:
    """Integrator of one model; one parameter vector may be swapped in per call."""

    system: System
    rtol: float = 1e-11
    atol: float = 1e-13
    locate: bool | None = None  # None: locate crossings when the model is piecewise
    _cache: OrderedDict = field(default_factory=OrderedDict, repr=False)

    def __post_init__(self):
        if self.locate is None:
            self.locate = self.system.piecewise

    def _compiled(self, x0, duration, t0, p, with_phi: bool):
        """(end state, monodromy or None, int trace J) by the compiled engine where the
        model's kinks are not located (module text); None where it does not apply (kinks
        on switching surfaces, or not a whole number of forcing periods)."""
        sys_ = self.system
        if not sys_.piecewise or sys_.contract.switching_surfaces:
            return None
        if p is not None:
            sys_ = replace(sys_, p=np.asarray(p, dtype=float))
        periods = duration / sys_.period
        m = int(round(periods))
        if m < 1 or abs(periods - m) > 1e-9 * periods:
            return None
        from ..integrate.run import integrate
        from ..integrate.spec import RunSpec

        spec = RunSpec(
            method="dop853",
            rtol=self.rtol,
            atol=self.atol,
            time="phase",
            t0=float(np.mod(sys_.omega * t0, 2.0 * np.pi)),
            transient=0,
            periods=m,
            valid_range="ignore",
            bound=1e6,
            collect=("samples", "exponent", "monodromy") if with_phi else ("samples",),
            lyapunov_periods=m if with_phi else 0,
            # a mesh grazing its contact edge (an unlocated kink) can take millions of
            # steps a period at these tolerances: such a flow is reported failed (its
            # caller's corrector stops there) rather than run for minutes
            max_steps=_MOST_STEPS_A_PERIOD * m,
        )
        x0 = np.asarray(x0, dtype=float)
        res = integrate(sys_, x0, spec)
        if res.status[0] != "ok":  # a failed integration, as CasADi's are: RuntimeError
            why = res.status[0]
            if why == "too many steps":
                why += (
                    f" (over {_MOST_STEPS_A_PERIOD:,} a period: a mesh grazing its contact "
                    "edge, whose kink the integrator does not locate)"
                )
            raise RuntimeError(f"the flow stopped: {why}")
        xf = np.asarray(res.x[0][-1], dtype=float)
        # trace J of linear dampers is free of the state and the time: checked at another
        # state and time than the start's (the end's would be the start's on an orbit)
        a = float(np.trace(sys_.module.jacobian(t0, x0, sys_.p)))
        b = float(np.trace(sys_.module.jacobian(t0 + 0.37 * duration, x0 + 0.1, sys_.p)))
        q = a * duration if abs(a - b) <= 1e-12 * max(1.0, abs(a)) else float("nan")
        return xf, (np.asarray(res.monodromy[0]) if with_phi else None), q

    def _located(self, x0, duration, t0, p, with_phi: bool):
        """DOP853 on (x, Phi, int trace J), restarted at every switching surface (the
        compiled engine where the model's kinks are not located: :meth:`_compiled`)."""
        done = self._compiled(x0, duration, t0, p, with_phi)
        if done is not None:
            return done
        sys_, n = self.system, self.system.n
        p = sys_.p if p is None else p
        k = n if with_phi else 0
        f = numpy_rhs(sys_.module, p, n, tangents=k)
        z0 = pack(x0, np.eye(n) if with_phi else None)
        done = integrate_located(
            f,
            t0,
            t0 + duration,
            z0,
            surfaces=sys_.contract.switching_surfaces,
            velocity=sys_.contract.velocity_of_state,
            method="DOP853",
            options={"rtol": self.rtol, "atol": self.atol},
            max_restarts=100_000,
        )
        return unpack(done.y, n, k)

    def _integrator(self, kind: str, duration: float) -> _Quiet:
        key = (kind, round(duration, 14))
        if key in self._cache:
            self._cache.move_to_end(key)
            return self._cache[key]
        import casadi as ca

        n, P = self.system.n, self.system.p.size
        dae = casadi_dae(self.system, tangents=n if kind == "variational" else 0, trace=True)
        opts = {
            "reltol": self.rtol,
            "abstol": self.atol,
            "max_num_steps": 2_000_000,
            "fsens_err_con": True,
            "show_eval_warnings": False,
            "disable_internal_warnings": True,
        }
        F = ca.integrator(f"flow_{kind}", "cvodes", dae, 0.0, duration, opts)
        if kind == "ad":
            x0 = ca.MX.sym("x0", n)
            pp = ca.MX.sym("pp", P + 1)
            out = F(x0=x0, p=pp)
            xf = out["xf"]
            F = ca.Function("flow_ad", [x0, pp], [xf, ca.jacobian(xf, x0), out["qf"]])
        F = _Quiet(F)  # CasADi's dumps of a failed integration stay off the terminal
        self._cache[key] = F
        if len(self._cache) > _CACHED_INTEGRATORS:
            self._cache.popitem(last=False)
        return F

    def __call__(self, x0, duration: float, t0: float = 0.0, p=None) -> np.ndarray:
        """End state after ``duration`` from ``x0`` at ``t0``."""
        if self.locate:
            return self._located(np.asarray(x0, float), duration, t0, p, False)[0]
        F = self._integrator("plain", duration)
        pp = np.concatenate([self.system.p if p is None else p, [t0]])
        return np.asarray(F(x0=np.asarray(x0, float), p=pp)["xf"]).ravel()

    def with_jacobian(
        self,
        x0,
        duration: float,
        t0: float = 0.0,
        p=None,
        method: str | None = None,
        fd_step: float = 1e-5,
    ):
        """(end state, d end / d start, int trace J) over ``duration`` from ``x0``.

        ``method`` defaults to ``"variational"`` when crossings are located (piecewise
        models), else ``"ad"``."""
        if method is None:
            method = "variational" if self.locate else "ad"
        if method not in MONODROMY_METHODS:
            raise ValueError(
                f"unknown monodromy method '{method}'; methods: {', '.join(MONODROMY_METHODS)}"
            )
        x0 = np.asarray(x0, float)
        n = x0.size
        pp = np.concatenate([self.system.p if p is None else p, [t0]])
        if method == "ad":
            xf, M, q = self._integrator("ad", duration)(x0, pp)
            return np.asarray(xf).ravel(), np.asarray(M), float(q)
        if method == "variational" and self.locate:
            return self._located(x0, duration, t0, p, True)
        if method == "variational":
            z0 = np.concatenate([x0, np.eye(n).ravel(order="F")])
            out = self._integrator("variational", duration)(x0=z0, p=pp)
            z = np.asarray(out["xf"]).ravel()
            return z[:n], z[n:].reshape((n, n), order="F"), float(out["qf"])
        # Central differences: truncation ~ h^2, integration noise ~ rtol / h.
        if self.locate:
            xf, _, q = self._located(x0, duration, t0, p, False)

            def end(x):
                return self._located(x, duration, t0, p, False)[0]
        else:
            F = self._integrator("plain", duration)
            out = F(x0=x0, p=pp)
            xf, q = np.asarray(out["xf"]).ravel(), float(out["qf"])

            def end(x):
                return np.asarray(F(x0=x, p=pp)["xf"]).ravel()

        M = np.empty((n, n))
        for j in range(n):
            e = np.zeros(n)
            e[j] = fd_step
            M[:, j] = (end(x0 + e) - end(x0 - e)) / (2 * fd_step)
        return xf, M, q


def monodromy_agreement(flow: FlowMap, x0, duration: float, t0: float = 0.0) -> dict:
    """The monodromy computed the three ways (AD, variational, finite differences) and
    how far apart they are: max difference over the largest entry, per pair."""
    mats = {m: flow.with_jacobian(x0, duration, t0, method=m)[1] for m in MONODROMY_METHODS}
    scale = np.max(np.abs(mats["ad"]))
    return {
        f"{a}_vs_{b}": float(np.max(np.abs(mats[a] - mats[b])) / scale)
        for a, b in (("ad", "variational"), ("ad", "fd"), ("variational", "fd"))
    }


@dataclass(eq=False)
class StroboscopicMap:
    """The period map ``P(x) = phi_{nT}(x; t0)`` of a forced system, T = 2 pi / omega.

    A map in its own right: ``P(x)``, its Jacobian (the monodromy matrix, with the
    integral of ``trace J`` for Liouville's check), iterates, and other parameter values
    through ``p`` without rebuilding the flow (the period follows ``p``'s omega).
    """

    system: System
    n: int = 1
    t0: float = 0.0
    flow: FlowMap | None = None

    def __post_init__(self):
        if self.n < 1:
            raise ValueError(f"the period multiple n must be >= 1, got {self.n}")
        if self.flow is None:
            self.flow = FlowMap(self.system)

    @property
    def dimension(self) -> int:
        return self.system.n

    def period(self, p=None) -> float:
        """``n T`` at the parameter vector ``p`` (default the system's)."""
        if p is None:
            return self.n * self.system.period
        w = p[self.system.contract.parameters.index(self.system.contract.forcing_frequency)]
        return self.n * (2.0 * np.pi / float(w))

    def __call__(self, x, p=None) -> np.ndarray:
        return self.flow(x, self.period(p), self.t0, p)

    def jacobian(self, x, p=None, method: str | None = None):
        """``(P(x), dP/dx, int trace J)``: the monodromy matrix at a fixed point."""
        return self.flow.with_jacobian(x, self.period(p), self.t0, p, method=method)

    def iterate(self, x, count: int, p=None) -> np.ndarray:
        """``count`` successive images of ``x``, shape (count, dimension)."""
        out = np.empty((count, self.dimension))
        for k in range(count):
            x = self(x, p)
            out[k] = x
        return out


class _Quiet:
    """A CasADi function called inside :func:`..integrate._quiet.quiet`: a failed integration raises
    (the caller reports it once) without CasADi's dump of its inputs on stderr."""

    def __init__(self, function):
        self.function = function

    def __call__(self, *args, **kwargs):
        with quiet():
            return self.function(*args, **kwargs)
