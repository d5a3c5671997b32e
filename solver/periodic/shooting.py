"""Periodic orbits of the forced system by shooting.

A period-n orbit (period nT, T = 2 pi / omega) through ``x0`` at time ``t0`` solves

    single shooting:    ``G(x0) = phi_{nT}(x0; t0) - x0 = 0``,
    multiple shooting:  ``x_{k+1} - phi_{nT/m}(x_k; t0 + k nT/m) = 0``, k = 0..m-1
                        (x_m = x_0),

by the damped Newton method of ``newton.py`` with the flow's Jacobian.  The residual is a
pure function :func:`residual` of the segment states, the period and the parameter
vector; the monodromy matrix (the product of the segment Jacobians) gives the Floquet
multipliers (``floquet.py``).

Minimal period.  A fixed point of ``phi_{nT}`` may be one of ``phi_{mT}`` for a divisor m
of n: shooting for period 3 from a guess near the period-1 orbit converges to it.
:func:`shoot` therefore records the orbit's minimal period (the smallest divisor m with
``phi_{mT}(x0) = x0``); :meth:`Orbit.reduced` re-solves such an orbit at its own period,
so that its multipliers are those of period m, not their n/m-th powers; and
:func:`search` tries guess after guess until it finds an orbit whose minimal period is
the requested one, returning the lower-period orbit (and saying so) when none is.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..integrate._quiet import quiet, reworded
from ..system import System
from .floquet import Floquet, floquet
from .flow import FlowMap
from .newton import NewtonError, newton

__all__ = [
    "Floquet",
    "Orbit",
    "OrbitSearch",
    "ShootingError",
    "floquet",
    "residual",
    "search",
    "shoot",
]

ShootingError = NewtonError  # what shooting raises: the history says how far it got


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
    minimal_period: int | None = None  # smallest m | n with phi_{mT}(x0) = x0 (None: unchecked)

    @property
    def period(self) -> float:
        return self.n * self.system.period

    def __repr__(self) -> str:
        f = self.floquet
        stab = "" if f is None else f", {f.stability or ('stable' if f.stable else 'unstable')}"
        top = "" if f is None else f", max |μ| {float(np.max(np.abs(f.multipliers))):.4g}"
        return (
            f"Orbit({self.system!r}: period-{self.n}, nT = {self.period:.6g} τ{stab}{top}, "
            f"residual {self.residual:.1e})"
        )

    def summary(self) -> str:
        """A few lines: the orbit, its start, Newton's convergence, the multipliers."""
        x0 = ", ".join(f"{s} = {v:.6g}" for s, v in zip(self.system.states, self.x0, strict=True))
        lines = [
            f"period-{self.n} orbit of {self.system!r}, period {self.period:.6g} τ"
            + (f" (minimal: {self.minimal_period}T)" if self.minimal_period else ""),
            f"x0 at τ = {self.t0:.6g}: {x0}",
            f"Newton: {self.iterations} iterations, residual {self.residual:.2e}, "
            f"{self.segments} segment(s)",
        ]
        f = self.floquet
        if f is not None:
            mu = sorted(f.multipliers, key=abs, reverse=True)
            text = ", ".join(f"{m.real:+.4f}{m.imag:+.4f}i" for m in mu[:6])
            lines.append(
                f"Floquet: {f.stability or ('stable' if f.stable else 'unstable')}, "
                f"critical |μ| = {abs(f.critical):.6f} ({f.kind}); "
                f"Liouville error {f.liouville_error:.1e}"
            )
            lines.append(f"multipliers: {text}" + (f" (+{len(mu) - 6})" if len(mu) > 6 else ""))
        return "\n".join(lines)

    def describe(self) -> dict:
        return {
            "n": self.n,
            "minimal_period": self.minimal_period,
            "period": self.period,
            "t0": self.t0,
            "x0": dict(zip(self.system.states, map(float, self.x0), strict=True)),
            "residual": self.residual,
            "iterations": self.iterations,
            "history": self.history,
            "segments": self.segments,
            "floquet": None if self.floquet is None else self.floquet.describe(),
            "values": {k: float(v) for k, v in self.system.values.items()},
        }

    def to_dict(self) -> dict:
        """:meth:`describe` with the model, its hash and the scales back to SI."""
        d = self.system.describe()
        return {
            "model": d["model"],
            "model_hash": d["model_hash"],
            "scales": self.system.scales(),
        } | self.describe()

    def smallest_period(self, flow: FlowMap | None = None, tol: float = 1e-8) -> int:
        """The smallest m dividing n with ``phi_{mT}(x0) = x0`` (to ``tol`` relative to
        the state's size): a period-n orbit found by shooting may be a period-m one.
        :func:`shoot` already records it as ``minimal_period``."""
        return _minimal_period(
            flow or FlowMap(self.system), self.system, self.x0, self.n, self.t0, tol
        )

    def reduced(self, **shoot_options) -> Orbit:
        """This orbit solved again at its minimal period (itself when that is n), so
        that its Floquet multipliers are the period-m ones."""
        m = self.minimal_period or self.n
        if m == self.n:
            return self
        return shoot(self.system, self.x0, m, t0=self.t0, **shoot_options)

    def to_table(self) -> tuple[list, list]:
        """One row per Floquet multiplier: real and imaginary parts, modulus."""
        mu = [] if self.floquet is None else self.floquet.multipliers
        return ["re", "im", "abs"], [[float(m.real), float(m.imag), float(abs(m))] for m in mu]

    def save(self, path):
        """Write to ``path``: ``.json``, ``.csv`` or ``.mat`` (see ``solver/export.py``)."""
        from ..export import save

        return save(self, path)


def residual(
    flow: FlowMap,
    X,
    T: float,
    p=None,
    *,
    t0: float = 0.0,
    segments: int = 1,
    monodromy: str | None = None,
):
    """The shooting residual ``G(X, T, p)`` and its Jacobian.

    ``X`` stacks the ``segments`` segment states (each of the model's size); each segment
    spans ``T / segments`` from ``t0 + k T / segments``.  Returns ``(G, dG/dX, blocks)``
    with ``blocks[k] = (segment Jacobian, integral of trace J over the segment)``.
    """
    N = flow.system.n
    dur = T / segments
    R = np.empty(segments * N)
    Jm = np.zeros((segments * N, segments * N))
    blocks = []
    for k in range(segments):
        xk = X[k * N : (k + 1) * N]
        with quiet():  # CasADi's dump of a failed integration: the error says it
            xe, Mk, q = flow.with_jacobian(xk, dur, t0 + k * dur, p, method=monodromy)
        blocks.append((Mk, q))
        nxt = (k + 1) % segments
        R[k * N : (k + 1) * N] = xe - X[nxt * N : (nxt + 1) * N]
        Jm[k * N : (k + 1) * N, k * N : (k + 1) * N] += Mk
        Jm[k * N : (k + 1) * N, nxt * N : (nxt + 1) * N] -= np.eye(N)
    return R, Jm, blocks


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
    flow's own (located variational equations for a piecewise model, else AD).  Pass
    ``flow`` to reuse one flow map (and its integrators) over many calls.
    """
    if n < 1 or segments < 1:
        raise ValueError("period multiple n and segments must be >= 1")
    x0 = np.asarray(x0, dtype=float)
    if x0.shape != (system.n,) or not np.all(np.isfinite(x0)):
        raise ValueError(f"x0 must be {system.n} finite numbers ({', '.join(system.states)})")
    flow = flow or FlowMap(system)
    try:
        return _shoot(system, x0, n, t0, segments, tol, max_iter, monodromy, flow)
    except NewtonError:
        raise
    except RuntimeError as err:  # CasADi's: a failed integration, said in one line
        raise NewtonError(reworded(err), []) from None


def _shoot(system, x0, n, t0, segments, tol, max_iter, monodromy, flow) -> Orbit:
    T = n * system.period
    dur = T / segments
    X = [np.asarray(x0, float)]
    for k in range(1, segments):
        with quiet():
            X.append(flow(X[-1], dur, t0 + (k - 1) * dur, system.p))
    X = np.concatenate(X)

    def fun(X):
        return residual(flow, X, T, system.p, t0=t0, segments=segments, monodromy=monodromy)

    found = newton(
        fun,
        X,
        tol=tol,
        max_iter=max_iter,
        singular="singular shooting Jacobian (a multiplier at +1?)",
    )
    N = system.n
    # Monodromy over the whole period: the product of the segment Jacobians.
    M = np.eye(N)
    q = 0.0
    for Mk, qk in found.extra:
        M = Mk @ M
        q += qk
    x = found.z[:N].copy()
    # The Newton tolerance sets how closely a lower period must close the orbit too.
    close = max(1e-8, 1e3 * tol)
    minimal = _minimal_period(flow, system, x, n, t0, close)
    return Orbit(
        system,
        found.z[:N].copy(),
        t0,
        n,
        found.residual,
        found.steps,
        found.history,
        M,
        floquet(M, q, rtol=flow.rtol),
        segments,
        minimal,
    )


def _minimal_period(flow: FlowMap, system: System, x0, n: int, t0: float, tol: float) -> int:
    """The smallest divisor m of n with ``|phi_{mT}(x0) - x0| <= tol max(1, |x0|)``."""
    scale = max(1.0, float(np.max(np.abs(x0))))
    for m in range(1, n):
        if n % m == 0:
            with quiet():
                end = flow(x0, m * system.period, t0, system.p)
            if np.max(np.abs(end - x0)) <= tol * scale:
                return m
    return n


@dataclass(frozen=True)
class OrbitSearch:
    """What :func:`search` found: ``orbit`` of minimal period ``requested`` (or None),
    else ``lower``, the first lower-period orbit the guesses led to (solved at its own
    period), and one record per guess tried."""

    requested: int
    orbit: Orbit | None
    lower: Orbit | None
    attempts: list = field(default_factory=list)

    @property
    def found(self) -> bool:
        return self.orbit is not None

    def to_dict(self) -> dict:
        best = self.orbit or self.lower
        return {
            "requested": self.requested,
            "found": self.found,
            "attempts": self.attempts,
            "orbit": None if best is None else best.to_dict(),
        }


def search(system: System, n: int, guesses, **shoot_options) -> OrbitSearch:
    """Shoot for period n from each guess in turn until the orbit's minimal period is n.

    ``guesses`` is an iterable of states (it may be lazy: a guess that costs a settling
    simulation is made only when needed).  Raises :class:`ShootingError` when no guess
    converges at all."""
    attempts, lower, last = [], None, None
    for k, guess in enumerate(guesses):
        try:
            orbit = shoot(system, guess, n, **shoot_options)
        except NewtonError as err:
            attempts.append({"guess": k, "outcome": f"no convergence: {err}"})
            last = err
            continue
        m = orbit.minimal_period or n
        attempts.append({"guess": k, "outcome": f"period-{m}"})
        if m == n:
            return OrbitSearch(n, orbit, None, attempts)
        if lower is None:
            lower = orbit.reduced(**shoot_options)
    if lower is None:
        tried = len(attempts)
        raise NewtonError(
            f"no guess converged ({tried} tried); last: {last}",
            [] if last is None else last.history,
        )
    return OrbitSearch(n, None, lower, attempts)
