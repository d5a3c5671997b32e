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
time domain: no finite differences.

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


class HarmonicBalance:
    """The discretised problem of one model, ``n`` and ``H``: the AFT matrices, the
    residual and its Jacobian as functions of the coefficients and the parameters.

    ``samples``: phases per base period for the AFT (default the smallest power of two
    of at least ``4 (2H + 1)``, so that the products in a cubic force are not aliased
    into the kept harmonics; raise it for stronger nonlinearities).
    """

    def __init__(self, system: System, harmonics: int, n: int = 1, samples: int | None = None):
        if harmonics < 0:
            raise ValueError(f"harmonics must be >= 0, got {harmonics}")
        if n < 1:
            raise ValueError(f"the period multiple n must be >= 1, got {n}")
        M = 2 * harmonics + 1
        N = samples or 1 << max(3, math.ceil(math.log2(4 * M)))
        if N <= 2 * harmonics:
            raise ValueError(f"samples ({N}) must exceed twice the harmonics ({harmonics})")
        self.system, self.H, self.n, self.N, self.M = system, harmonics, n, N, M
        s = 2 * np.pi * np.arange(N) / N
        k = np.arange(1, harmonics + 1)
        E = np.empty((N, M))
        E[:, 0] = 1.0
        E[:, 1::2] = np.cos(np.outer(s, k))
        E[:, 2::2] = np.sin(np.outer(s, k))
        self.phases, self.E = s, E
        self.P = E.T * np.r_[1.0, np.full(2 * harmonics, 2.0)][:, None] / N
        # d/ds on the coefficients: (c_k, s_k) -> (k s_k, -k c_k)
        D = np.zeros((M, M))
        for kk in k:
            D[2 * kk - 1, 2 * kk] = kk
            D[2 * kk, 2 * kk - 1] = -kk
        self.Ds = D
        # where w D sits in the (nx M) square Jacobian: the diagonal blocks' nonzeros
        nz = np.flatnonzero(D)
        rows, cols = np.divmod(nz, M)
        n_states = system.n
        self._dflat = np.tile(nz, n_states)
        blocks = np.repeat(np.arange(n_states) * M, nz.size)
        self._diag = (blocks + np.tile(rows, n_states), blocks + np.tile(cols, n_states))

    def omega(self, p) -> float:
        return float(p[self.system.module.PARAMETERS.index(self.system.contract.forcing_frequency)])

    def times(self, p) -> np.ndarray:
        """The AFT's sample times tau_j over one period n T."""
        return self.n * self.phases / self.omega(p)

    def residual(self, X: np.ndarray, p, jacobian: bool = True):
        """``R`` (states x M) and, with ``jacobian``, ``dR/dX`` ((states M) square, rows
        and columns state-major)."""
        mod, nx = self.system.module, self.system.n
        w = self.omega(p) / self.n
        tau = self.times(p)
        x = self.synthesis(X)  # (nx, N)
        F = np.broadcast_to(np.asarray(mod.rhs(tau, x, p), float).reshape(nx, -1), x.shape)
        R = w * X @ self.Ds.T - self.analysis(F)
        if not jacobian:
            return R, None
        A = self.toeplitz(self._jacobian(tau, x, p))
        Jac = -A.reshape(nx * self.M, nx * self.M)
        Jac[self._diag] += w * self.Ds.ravel()[self._dflat]
        return R, Jac

    def synthesis(self, X: np.ndarray) -> np.ndarray:
        """The series at the N phases by the inverse real FFT (rows: states)."""
        H, N = self.H, self.N
        Z = np.zeros((X.shape[0], N // 2 + 1), dtype=complex)
        Z[:, 0] = X[:, 0] * N
        Z[:, 1 : H + 1] = (X[:, 1::2] - 1j * X[:, 2::2]) * (N / 2)
        return np.fft.irfft(Z, n=N, axis=1)

    def analysis(self, F: np.ndarray) -> np.ndarray:
        """The kept Fourier coefficients of samples at the N phases by the real FFT (exact
        for the harmonics up to H with N > 2H)."""
        G = np.fft.rfft(F, axis=1) / self.N
        out = np.empty((F.shape[0], self.M))
        out[:, 0] = G[:, 0].real
        out[:, 1::2] = 2 * G[:, 1 : self.H + 1].real
        out[:, 2::2] = -2 * G[:, 1 : self.H + 1].imag
        return out

    def toeplitz(self, J: np.ndarray, harmonics: int | None = None) -> np.ndarray:
        """``P diag(J) E`` for every pair of states, (nx, M, nx, M), from the discrete
        Fourier coefficients of ``J`` (exact on the AFT grid: with ``N > 4H`` the sums and
        differences of two kept harmonics are not aliased).  With ``Jh_l`` the DFT
        coefficient of harmonic l: cos-cos ``Re Jh_{k-m} + Re Jh_{k+m}``, cos-sin
        ``Im Jh_{k-m} - Im Jh_{k+m}``, sin-cos ``-Im Jh_{k-m} - Im Jh_{k+m}``, sin-sin
        ``Re Jh_{k-m} - Re Jh_{k+m}`` (rows k, columns m >= 1); row 0 and column 0 from
        ``Jh_m`` and ``2 Jh_k``.  ``harmonics``: keep only the first (Hill's matrix of a
        smaller size)."""
        H = self.H if harmonics is None else harmonics
        nx, M = J.shape[0], 2 * H + 1
        if 2 * H >= self.N // 2:  # few samples: the sums would alias, use the products
            keep = slice(0, M)
            return np.einsum("kj,abj,jm->akbm", self.P[keep], J, self.E[:, keep], optimize=True)
        Jh = np.fft.rfft(J, axis=-1) / self.N  # (nx, nx, N/2 + 1), l = 0..N/2
        re, im = Jh.real, Jh.imag
        k = np.arange(1, H + 1)
        d = k[:, None] - k[None, :]
        a = np.abs(d)
        sg = np.sign(d)
        sm = k[:, None] + k[None, :]
        T = np.empty((nx, nx, M, M))
        T[..., 0, 0] = re[..., 0]
        T[..., 0, 1::2] = re[..., k]
        T[..., 0, 2::2] = -im[..., k]
        T[..., 1::2, 0] = 2 * re[..., k]
        T[..., 2::2, 0] = -2 * im[..., k]
        im_d = im[..., a] * sg  # Im Jh_{k-m} (odd in the index)
        T[..., 1::2, 1::2] = re[..., a] + re[..., sm]
        T[..., 1::2, 2::2] = im_d - im[..., sm]
        T[..., 2::2, 1::2] = -im_d - im[..., sm]
        T[..., 2::2, 2::2] = re[..., a] - re[..., sm]
        return T.transpose(0, 2, 1, 3)

    def _jacobian(self, tau, x, p) -> np.ndarray:
        """The generated Jacobian at the AFT samples, (nx, nx, N) (a constant one too)."""
        nx = self.system.n
        J = np.asarray(self.system.module.jacobian(tau, x, p), dtype=float)
        return np.broadcast_to(J.reshape(nx, nx, -1), (nx, nx, x.shape[1]))

    def hill_matrix(self, X, p, harmonics: int | None = None, J=None) -> np.ndarray:
        """``A_hat - (omega/n) D`` (= -dR/dX with all H harmonics): its eigenvalues are the
        Floquet exponents, shifted.  ``harmonics`` < H keeps the central part only (J of
        the whole solution, perturbations with fewer harmonics); ``J``: the Jacobian at
        the AFT samples when already known."""
        Hh = self.H if harmonics is None else min(harmonics, self.H)
        nx, Mh = self.system.n, 2 * Hh + 1
        if J is None:
            J = self._jacobian(self.times(p), X @ self.E.T, p)
        A = self.toeplitz(J, Hh).reshape(nx * Mh, nx * Mh)
        w = self.omega(p) / self.n
        D = self.Ds[:Mh, :Mh]
        for a in range(nx):
            A[a * Mh : (a + 1) * Mh, a * Mh : (a + 1) * Mh] -= w * D
        return A

    def time_series(self, X, phases) -> np.ndarray:
        """The states at the phases ``s`` (radians of the base period), (states, len)."""
        s = np.atleast_1d(np.asarray(phases, float))
        k = np.arange(1, self.H + 1)
        B = np.empty((s.size, self.M))
        B[:, 0] = 1.0
        B[:, 1::2] = np.cos(np.outer(s, k))
        B[:, 2::2] = np.sin(np.outer(s, k))
        return X @ B.T


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

    def _dense(self, name: str, points: int = 1024) -> np.ndarray:
        i = self.system.index(name)
        s = 2 * np.pi * np.arange(points) / points
        return self._problem().time_series(self.coefficients[i : i + 1], s)[0]

    def mean(self, name: str) -> float:
        return float(self.coefficients[self.system.index(name), 0])

    def amplitude(self, name: str) -> float:
        """Half the peak-to-peak value of ``name`` over the period (1024 phases)."""
        y = self._dense(name)
        return float((y.max() - y.min()) / 2)

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
            "period_multiple": self.n,
            "harmonics": self.harmonics,
            "samples": self.samples,
            "residual": self.residual,
            "newton_iterations": self.iterations,
            "tail_share": self.tail_share(),
            "values": {k: float(v) for k, v in self.system.values.items()},
            "coordinates": {
                c: {"mean": self.mean(c), "amplitude": self.amplitude(c), "rms": self.rms(c)}
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
        sol = harmonic_balance(system, guess, harmonics=harmonics, n=n, samples=samples,
                               tol=tol, max_iter=max_iter, stability=False)  # fmt: skip
        while sol.tail_share() > tail and 2 * sol.harmonics <= max_harmonics:
            sol = harmonic_balance(system, sol.coefficients, harmonics=2 * sol.harmonics, n=n,
                                   tol=tol, max_iter=max_iter, stability=False)  # fmt: skip
        return harmonic_balance(system, sol.coefficients, harmonics=sol.harmonics, n=n,
                                samples=samples if sol.harmonics == harmonics else None,
                                tol=tol, max_iter=max_iter, stability=stability)  # fmt: skip
    problem = HarmonicBalance(system, harmonics, n, samples)
    p = system.p
    X0 = _initial_coefficients(problem, guess, p)
    shape = X0.shape

    def fun(z):
        R, Jac = problem.residual(z.reshape(shape), p)
        return R.ravel(), Jac, None

    try:
        found = newton(fun, X0.ravel(), tol=tol, max_iter=max_iter, min_steps=1,
                       singular="singular harmonic-balance Jacobian (at a fold?)")  # fmt: skip
    except NewtonError as err:
        raise HarmonicBalanceError(
            f"harmonic balance did not converge ({err}); try another guess, more "
            "harmonics or more samples"
        ) from None
    X = found.z.reshape(shape)
    sol = HBSolution(system, n, harmonics, problem.N, X, found.residual, found.steps,
                     history=found.history)  # fmt: skip
    if not stability:
        return sol
    sig, fl = hill(problem, X, p, error=sol.tail_share())
    return dataclasses.replace(sol, floquet=fl, exponents=sig)
