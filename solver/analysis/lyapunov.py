"""Largest Lyapunov exponent from the variational equations (Benettin's method).

The state and one tangent vector are integrated together,

    ``x' = F(tau, x, p)``,   ``w' = J(tau, x, p) w``,

over one forcing period at a time -- with the compiled DOP853 (``integrate/native``) when a
C compiler is available, else with CasADi's CVODES on the variational system of
``integrate/variational.py``; after each period the tangent
vector is renormalised and ``log |w|`` accumulated (Benettin, Galgani, Giorgilli and
Strelcyn 1980, "Lyapunov characteristic exponents for smooth dynamical systems",
Meccanica 15).  The exponent is per unit of non-dimensional time tau; the running
estimate is returned so that its convergence can be judged.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..integrate import native
from ..integrate.variational import casadi_dae
from ..system import System

__all__ = ["LyapunovEstimate", "largest_lyapunov"]


@dataclass(frozen=True)
class LyapunovEstimate:
    exponent: float
    running: np.ndarray  # estimate after each period
    periods: int
    spread: float  # max - min of the running estimate over its last half
    rtol: float = 1e-8
    atol: float = 1e-10
    integrator: str = "CVODES"

    def describe(self) -> dict:
        return {
            "exponent": self.exponent,
            "periods": self.periods,
            "last_half_spread": self.spread,
            "units": "per unit tau",
            "method": f"Benettin, variational equations, {self.integrator}",
            "rtol": self.rtol,
            "atol": self.atol,
        }

    to_dict = describe


def largest_lyapunov(
    system: System,
    x0: np.ndarray,
    *,
    t0: float = 0.0,
    periods: int = 200,
    rtol: float = 1e-8,
    atol: float = 1e-10,
    seed: int = 0,
    backend: str = "auto",
) -> LyapunovEstimate:
    """Benettin estimate of the largest exponent from ``x0`` at time ``t0`` (which should
    lie on the attractor: pass the end of a transient).  ``backend``: ``native``
    (compiled DOP853), ``cvodes``, or ``auto`` (native when a C compiler is available)."""
    if backend not in ("auto", "native", "cvodes"):
        raise ValueError(f"backend must be 'auto', 'native' or 'cvodes', got {backend!r}")
    n = system.n
    rng = np.random.default_rng(seed)
    v = rng.standard_normal(n)
    v /= np.linalg.norm(v)
    if backend != "cvodes":
        try:
            running, _ = native.benettin(
                system.module,
                system.p,
                np.concatenate([np.asarray(x0, float), v]),
                t0=t0,
                period=system.period,
                periods=periods,
                rtol=rtol,
                atol=atol,
            )
        except native.NativeUnavailable:
            if backend == "native":
                raise
        else:
            half = running[periods // 2 :]
            return LyapunovEstimate(
                float(running[-1]),
                running,
                periods,
                float(half.max() - half.min()),
                rtol,
                atol,
                "compiled DOP853",
            )
    import casadi as ca

    # Each period is integrated from 0 with the forcing shifted to start at t0 + k T.
    dae = casadi_dae(system, tangents=1)
    T = system.period
    F = ca.integrator(
        "period",
        "cvodes",
        dae,
        0.0,
        T,
        {"reltol": rtol, "abstol": atol, "max_num_steps": 1_000_000},
    )
    z = np.concatenate([np.asarray(x0, dtype=float), v])
    total = 0.0
    running = np.empty(periods)
    for k in range(periods):
        z = np.asarray(F(x0=z, p=np.concatenate([system.p, [t0 + k * T]]))["xf"]).ravel()
        growth = np.linalg.norm(z[n:])
        if not np.isfinite(growth) or growth == 0:
            raise FloatingPointError(f"tangent vector degenerated after {k + 1} periods")
        total += np.log(growth)
        z[n:] /= growth
        running[k] = total / ((k + 1) * T)
    half = running[periods // 2 :]
    return LyapunovEstimate(
        float(running[-1]), running, periods, float(half.max() - half.min()), rtol, atol
    )
