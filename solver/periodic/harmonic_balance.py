"""Harmonic balance for any generated model, with Hill's method for stability.

The periodic solution of ``x' = f(tau, x; p)`` with period ``n T`` (``T = 2 pi / omega``,
``n = 1`` for period-1, ``n > 1`` for a subharmonic orbit) is written in the phase
``s = omega tau / n`` as a truncated real Fourier series per state,

    x_a(s) = c_a0 + sum_{k=1..H} (c_ak cos k s + s_ak sin k s),

the unknowns ``X`` (states x ``2H + 1``, columns ``c0, c1, s1, c2, s2, ...``).  The residual
``R(X) = D X - P f(tau_j, E X)`` balances the derivative (``D``, exact on the series) against
the nonlinear force by the alternating frequency-time scheme (Cameron and Griffin 1989,
"An alternating frequency/time domain method for calculating the steady-state response of
nonlinear dynamic systems", J. Appl. Mech. 56): ``E`` (the inverse real FFT) evaluates
the series at ``N`` equally spaced phases, the generated right-hand side is evaluated
there, and ``P`` (the real FFT, exact for ``N > 2H``) takes the force back.  The Jacobian is
``dR/dX = D - P diag(J(tau_j)) E`` block by block, with ``J`` the generated Jacobian in the
time domain: no finite differences.  The discretisation is :class:`~.aft.HarmonicBalance`
(``aft.py``); this module solves it.

Stability (Hill's method): a perturbation ``y = exp(sigma tau) q(s)`` with ``q`` periodic
solves ``(A_hat - D) q = sigma q`` with ``A_hat = P diag(J) E``, so the eigenvalues of
``-dR/dX`` are the Floquet exponents, each repeated shifted by ``i k omega / n``.  The
physical ones are chosen by their eigenvectors' symmetry (von Groll and Ewins 2001, "The
harmonic balance method with arc-length continuation in rotor/stator contact problems",
J. Sound Vib. 241): written in complex harmonics ``-H..H``, a copy shifted by ``k``
has its weight centred on ``-k``; the ``n_states`` exponents whose weight is centred
nearest harmonic 0 (distinct multipliers) are kept, and the multipliers are
``exp(sigma n T)``.  The shooting monodromy cross-checks them (``tests/solver``).

A model with a dead zone (piecewise-linear force) converges slowly in ``H``: its force has
a kink, so its Fourier coefficients fall off only like ``k^-2``; ``tail_share`` reports
what the highest harmonics still carry so that ``H`` can be raised until it is small.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field

import numpy as np

from ..system import System
from .aft import HarmonicBalance
from .floquet import Floquet
from .hill import HILL_HARMONICS, hill
from .newton import NewtonError, newton

__all__ = [
    "HarmonicBalance",
    "HarmonicBalanceError",
    "HBSolution",
    "harmonic_balance",
    "hill",
    "HILL_HARMONICS",
]


class HarmonicBalanceError(RuntimeError):
    """The harmonic-balance equations did not converge (the message says what to try)."""


@dataclass(frozen=True)
class HBSolution:
    """A harmonic-balance solution: the coefficients (states x ``2H + 1``), the residual's
    max-norm, the Newton steps, and Hill's stability when asked for."""

    system: System
    n: int
    harmonics: int
    samples: int
    coefficients: np.ndarray
    residual: float
    iterations: int
    floquet: Floquet | None = None
    exponents: np.ndarray | None = None
    history: list = field(default_factory=list)

    @property
    def period(self) -> float:
        return self.n * self.system.period

    def _problem(self) -> HarmonicBalance:
        return HarmonicBalance(self.system, self.harmonics, self.n, self.samples)

    def at(self, tau) -> np.ndarray:
        """The states at times ``tau`` (any shape of ``tau``; result (states, ...))."""
        tau = np.asarray(tau, float)
        s = self.system.omega * tau.ravel() / self.n
        return self._problem().time_series(self.coefficients, s).reshape((-1, *tau.shape))

    def state(self, t0: float = 0.0) -> np.ndarray:
        """The state at ``t0`` (a shooting start, for example)."""
        return self.at(np.array([t0]))[:, 0]

    def extremes(self, name: str) -> tuple[float, float]:
        """The smallest and largest value of ``name`` over the period n T, at the extrema
        of its trigonometric polynomial (refined, :meth:`~.aft.HarmonicBalance.extrema`)."""
        i = self.system.index(name)
        lo, hi = self._problem().extrema(self.coefficients[i : i + 1])
        return float(lo[0]), float(hi[0])

    def mean(self, name: str) -> float:
        return float(self.coefficients[self.system.index(name), 0])

    def amplitude(self, name: str) -> float:
        """Half the peak-to-peak value of ``name`` over the period, ``(max - min) / 2``
        at the refined extrema (:meth:`extremes`)."""
        lo, hi = self.extremes(name)
        return (hi - lo) / 2

    def rms(self, name: str) -> float:
        """Root mean square of ``name`` (Parseval, exact on the series)."""
        c = self.coefficients[self.system.index(name)]
        return float(math.sqrt(c[0] ** 2 + 0.5 * np.sum(c[1:] ** 2)))

    def harmonic_amplitudes(self, name: str) -> np.ndarray:
        """|c_k + i s_k| for k = 0..H (k = 0: the mean's size)."""
        c = self.coefficients[self.system.index(name)]
        return np.r_[abs(c[0]), np.hypot(c[1::2], c[2::2])]

    def tail_share(self, top: int | None = None) -> float:
        """The share of the response (of the non-constant part, in the RMS sense, largest
        over the coordinates) that the highest ``top`` harmonics (default a quarter of H,
        at least one) carry: small means H resolves the solution."""
        top = top or max(1, self.harmonics // 4)
        share = 0.0
        for c in self.system.coordinates:
            a = self.harmonic_amplitudes(c)[1:]
            total = float(np.sum(a**2))
            if total > 0:
                share = max(share, float(np.sqrt(np.sum(a[-top:] ** 2) / total)))
        return share

    def describe(self) -> dict:
        return {
            "method": "harmonic balance (AFT)",
            "n": self.n,
            "harmonics": self.harmonics,
            "samples": self.samples,
            "residual": self.residual,
            "iterations": self.iterations,
            "tail_share": self.tail_share(),
            "values": {k: float(v) for k, v in self.system.values.items()},
            "coordinates": {
                c: {
                    "mean": self.mean(c),
                    "amplitude": self.amplitude(c),
                    "rms": self.rms(c),
                    "min": self.extremes(c)[0],
                    "max": self.extremes(c)[1],
                }
                for c in self.system.coordinates
            },
            "stable": None if self.floquet is None else self.floquet.stable,
            "floquet": None if self.floquet is None else self.floquet.describe(),
        }


def _initial_coefficients(problem: HarmonicBalance, guess, p) -> np.ndarray:
    system = problem.system
    if guess is None:
        from ..integrate import default_initial_state, simulate

        tr = simulate(
            system,
            default_initial_state(system),
            transient=200,
            periods=problem.n,
            samples_per_period=64,
        )
        if tr.status != "ok":
            raise HarmonicBalanceError(
                f"no start for harmonic balance: the run to a steady state ended "
                f"'{tr.status}'; give a guess (coefficients or a state on the orbit)"
            )
        guess = tr
    if hasattr(guess, "x") and hasattr(guess, "t"):  # a Trajectory: its last n periods
        x, t = np.asarray(guess.x), np.asarray(guess.t)
        span = problem.n * system.period
        keep = t >= t[-1] - span * (1 - 1e-12)
        s = (system.omega * t[keep] / problem.n) % (2 * np.pi)
        B = problem.time_series(np.eye(problem.M), s).T  # (len, M)
        coef, *_ = np.linalg.lstsq(B, x[:, keep].T, rcond=None)
        return coef.T
    X = np.asarray(guess, float)
    if X.shape == (system.n,):  # a state on the orbit at tau = 0: integrate one period
        from ..integrate import simulate

        tr = simulate(
            system, X, transient=0, periods=problem.n, samples_per_period=max(64, problem.N)
        )
        return _initial_coefficients(problem, tr, p)
    if X.shape[0] != system.n:
        raise ValueError(f"guess: {system.n} rows of coefficients expected, got {X.shape}")
    out = np.zeros((system.n, problem.M))
    m = min(problem.M, X.shape[1])
    out[:, :m] = X[:, :m]
    return out


def harmonic_balance(
    system: System,
    guess=None,
    *,
    harmonics: int = 10,
    n: int = 1,
    samples: int | None = None,
    tol: float = 1e-10,
    max_iter: int = 40,
    stability: bool = True,
    tail: float | None = None,
    max_harmonics: int = 256,
) -> HBSolution:
    """The period-``n T`` solution of ``system`` by harmonic balance with ``harmonics``
    harmonics of ``omega / n``.

    ``guess``: None (integrate to a steady state and project its last ``n`` periods),
    a trajectory, a state on the orbit at ``tau = 0``, or coefficients (states x
    ``2H' + 1``, padded or cut to ``2H + 1``).  Newton on the residual's max-norm to
    ``tol``; Hill's stability with ``stability``.  ``tail``: double H (from the last
    solution, up to ``max_harmonics``) until the highest quarter of the harmonics carries
    at most this share of the response (:meth:`HBSolution.tail_share`).
    """
    if tail is not None:
        if not tail > 0:
            raise ValueError(f"tail must be a positive share, got {tail}")
        sol = harmonic_balance(
            system,
            guess,
            harmonics=harmonics,
            n=n,
            samples=samples,
            tol=tol,
            max_iter=max_iter,
            stability=False,
        )
        while sol.tail_share() > tail and 2 * sol.harmonics <= max_harmonics:
            sol = harmonic_balance(
                system,
                sol.coefficients,
                harmonics=2 * sol.harmonics,
                n=n,
                tol=tol,
                max_iter=max_iter,
                stability=False,
            )
        return harmonic_balance(
            system,
            sol.coefficients,
            harmonics=sol.harmonics,
            n=n,
            samples=samples if sol.harmonics == harmonics else None,
            tol=tol,
            max_iter=max_iter,
            stability=stability,
        )
    problem = HarmonicBalance(system, harmonics, n, samples)
    p = system.p
    X0 = _initial_coefficients(problem, guess, p)
    shape = X0.shape

    def fun(z):
        R, Jac = problem.residual(z.reshape(shape), p)
        return R.ravel(), Jac, None

    try:
        found = newton(
            fun,
            X0.ravel(),
            tol=tol,
            max_iter=max_iter,
            min_steps=1,
            singular="singular harmonic-balance Jacobian (at a fold?)",
        )
    except NewtonError as err:
        raise HarmonicBalanceError(
            f"harmonic balance did not converge ({err}); try another guess, more "
            "harmonics or more samples"
        ) from None
    X = found.z.reshape(shape)
    sol = HBSolution(
        system, n, harmonics, problem.N, X, found.residual, found.steps, history=found.history
    )
    if not stability:
        return sol
    sig, fl = hill(problem, X, p, error=sol.tail_share())
    return dataclasses.replace(sol, floquet=fl, exponents=sig)
