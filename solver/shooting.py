"""Periodic orbits of the forced system: shooting and Floquet multipliers.

A period-n orbit (period nT, T = 2 pi / omega) through ``x0`` at time ``t0`` solves

    single shooting:    ``G(x0) = phi_{nT}(x0; t0) - x0 = 0``,
    multiple shooting:  ``x_{k+1} - phi_{nT/m}(x_k; t0 + k nT/m) = 0``, k = 0..m-1
                        (x_m = x_0),

by Newton's method with the flow's Jacobian, damped by backtracking on the residual norm.
The monodromy matrix M (the Jacobian of the period map) gives the Floquet multipliers;
the orbit is stable when all lie inside the unit circle, and the critical multiplier
(largest modulus) names how stability is lost: +1 fold (saddle-node), -1 period
doubling, a complex pair Neimark-Sacker.  Liouville's formula ``det M =
exp(int_0^{nT} trace J dtau)`` is checked for every orbit, in logarithms
(``|log det M - int trace J|``, about the relative error of det M).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from .flow import FlowMap
from .system import System

__all__ = ["Floquet", "Orbit", "ShootingError", "floquet", "shoot"]


class ShootingError(RuntimeError):
    """Newton's method did not converge; the history says how far it got."""

    def __init__(self, message: str, history: list):
        super().__init__(message)
        self.history = history


@dataclass(frozen=True)
class Floquet:
    multipliers: np.ndarray
    stable: bool
    critical: complex
    kind: str  # "fold", "period-doubling", "neimark-sacker" (type of the critical multiplier)
    liouville_error: float  # |log|det M| - int trace J|, ~ the relative error of det M

    def describe(self) -> dict:
        return {
            "multipliers": [
                {"re": float(m.real), "im": float(m.imag), "abs": float(abs(m))}
                for m in self.multipliers
            ],  # fmt: skip
            "stable": self.stable,
            "critical": {
                "re": float(self.critical.real),
                "im": float(self.critical.imag),
                "abs": float(abs(self.critical)),
            },  # fmt: skip
            "critical_type": self.kind,
            "liouville_error": self.liouville_error,
            "liouville_error_meaning": "|log det M - integral of trace J over the period|; "
            "null when round-off has taken det M (multipliers near zero)",
        }


def floquet(M: np.ndarray, trace_integral: float) -> Floquet:
    """Multipliers of monodromy ``M``, stability, critical type and Liouville's check."""
    mu = np.linalg.eigvals(M)
    mu = mu[np.argsort(-np.abs(mu))]
    crit = complex(mu[0])
    if abs(crit.imag) > 1e-9 * max(1.0, abs(crit)):
        kind = "neimark-sacker"
    else:
        kind = "fold" if crit.real > 0 else "period-doubling"
    # Compared in logarithms: over long periods det M underflows long before its log does.
    sign, logdet = np.linalg.slogdet(M)
    error = abs(logdet - trace_integral) if sign > 0 else math.inf
    return Floquet(mu, bool(abs(crit) < 1.0), crit, kind, float(error))


@dataclass(frozen=True)
class Orbit:
    """A periodic orbit: initial state at ``t0``, period n T, and its stability."""

    system: System
    x0: np.ndarray
    t0: float
    n: int
    residual: float
    iterations: int
    history: list = field(default_factory=list)
    monodromy: np.ndarray | None = None
    floquet: Floquet | None = None
    segments: int = 1

    @property
    def period(self) -> float:
        return self.n * self.system.period

    def describe(self) -> dict:
        return {
            "period_multiple": self.n,
            "period_tau": self.period,
            "t0": self.t0,
            "x0": dict(zip(self.system.states, map(float, self.x0), strict=True)),
            "residual": self.residual,
            "newton_iterations": self.iterations,
            "history": self.history,
            "segments": self.segments,
            "floquet": None if self.floquet is None else self.floquet.describe(),
            "values": {k: float(v) for k, v in self.system.values.items()},
        }


def shoot(
    system: System,
    x0,
    n: int = 1,
    *,
    t0: float = 0.0,
    segments: int = 1,
    tol: float = 1e-11,
    max_iter: int = 30,
    monodromy: str | None = None,
    flow: FlowMap | None = None,
) -> Orbit:
    """Newton shooting for the period-n orbit near ``x0`` (at time ``t0``).

    ``segments`` > 1 uses multiple shooting: the initial segment states come from
    integrating the guess.  Converged when the residual's max-norm is below ``tol``.
    ``monodromy`` picks the route (``ad``, ``variational``, ``fd``); by default the
    flow's own (located variational equations for a dead zone, else AD).
    """
    if n < 1 or segments < 1:
        raise ValueError("period multiple n and segments must be >= 1")
    flow = flow or FlowMap(system)
    dur = n * system.period / segments
    N = system.n
    X = [np.asarray(x0, float)]
    for k in range(1, segments):
        X.append(flow(X[-1], dur, t0 + (k - 1) * dur))
    X = np.concatenate(X)

    def residual_and_jacobian(X):
        R = np.empty(segments * N)
        Jm = np.zeros((segments * N, segments * N))
        blocks = []
        for k in range(segments):
            xk = X[k * N : (k + 1) * N]
            xe, Mk, q = flow.with_jacobian(xk, dur, t0 + k * dur, method=monodromy)
            blocks.append((Mk, q))
            nxt = (k + 1) % segments
            R[k * N : (k + 1) * N] = xe - X[nxt * N : (nxt + 1) * N]
            Jm[k * N : (k + 1) * N, k * N : (k + 1) * N] += Mk
            Jm[k * N : (k + 1) * N, nxt * N : (nxt + 1) * N] -= np.eye(N)
        return R, Jm, blocks

    history = []
    R, Jm, blocks = residual_and_jacobian(X)
    norm = float(np.max(np.abs(R)))
    history.append(norm)
    it = 0
    while norm > tol:
        if it >= max_iter or not np.isfinite(norm):
            raise ShootingError(f"Newton did not converge in {it} iterations (residual "
                                f"{norm:.3g})", history)  # fmt: skip
        try:
            step = np.linalg.solve(Jm, -R)
        except np.linalg.LinAlgError:
            raise ShootingError("singular shooting Jacobian (a multiplier at +1?)",
                                history) from None  # fmt: skip
        # Backtracking: halve the step until the residual decreases.
        lam = 1.0
        while True:
            trial = X + lam * step
            Rt, Jt, bt = residual_and_jacobian(trial)
            nt = float(np.max(np.abs(Rt)))
            if nt < norm:
                break
            lam /= 2
            if lam < 1e-4:
                raise ShootingError(f"Newton's line search found no decrease of the residual "
                                    f"({norm:.3g}) after {it} iterations", history)  # fmt: skip
        X, R, Jm, blocks, norm = trial, Rt, Jt, bt, nt
        it += 1
        history.append(norm)
    # Monodromy over the whole period: the product of the segment Jacobians.
    M = np.eye(N)
    q = 0.0
    for Mk, qk in blocks:
        M = Mk @ M
        q += qk
    return Orbit(system, X[:N].copy(), t0, n, norm, it, history, M, floquet(M, q), segments)
