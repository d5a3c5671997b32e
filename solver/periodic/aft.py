"""The harmonic-balance discretisation of one model: the alternating frequency-time scheme
(Cameron and Griffin 1989, "An alternating frequency/time domain method for calculating
the steady-state response of nonlinear dynamic systems", J. Appl. Mech. 56).

The unknowns ``X`` (states x ``2H + 1``, columns ``c0, c1, s1, c2, s2, ...``) are the
truncated real Fourier series of each state in the phase ``s = omega tau / n``.  The
residual ``R(X) = D X - P f(tau_j, E X)`` balances the derivative (``D``, exact on the
series) against the force: ``E`` (the inverse real FFT) evaluates the series at ``N``
equally spaced phases, the generated right-hand side is evaluated there, and ``P`` (the
real FFT, exact for ``N > 2H``) takes the force back.  The Jacobian is
``dR/dX = D - P diag(J(tau_j)) E`` block by block, with ``J`` the generated Jacobian in
the time domain: no finite differences.  ``harmonic_balance.py`` solves it, ``hill.py``
judges the solution's stability, ``hb_continuation.py`` continues it.
"""

from __future__ import annotations

import math

import numpy as np

from ..system import System

__all__ = ["HarmonicBalance"]


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

    def extrema(self, X) -> tuple[np.ndarray, np.ndarray]:
        """The smallest and the largest value over the period of each row of ``X``
        ((rows, 2H + 1) coefficients; two arrays (rows,)), read off the trigonometric
        polynomial itself, not off samples of it.

        The extremes are first found on ``max(64, 8 (2H + 1))`` equally spaced phases
        (about 16 a period of the highest harmonic, so the sample nearest each extreme
        lies in its basin) and then refined by Newton's method on ``x'(s) = 0`` with the
        exact derivatives ``x'(s) = sum k (s_k cos ks - c_k sin ks)`` and ``x''(s) = -sum
        k^2 (c_k cos ks + s_k sin ks)``, kept within one sample of the start; a refined
        value never replaces a better sampled one.  Converges quadratically: a sampled
        half peak-to-peak is off by ``O(h^2 x'')`` (1.9e-5 on a linear oscillator at 512
        phases), the refined one by rounding."""
        X = np.atleast_2d(np.asarray(X, float))
        grid = max(64, 8 * self.M)
        h = 2 * np.pi / grid
        s = h * np.arange(grid)
        y = self.time_series(X, s)
        lo = np.minimum(y.min(axis=1), self._refine(X, s[np.argmin(y, axis=1)], h))
        hi = np.maximum(y.max(axis=1), self._refine(X, s[np.argmax(y, axis=1)], h))
        return lo, hi

    def _refine(self, X, start, h, iterations: int = 8) -> np.ndarray:
        """The value at the stationary point within ``start +- h`` of each row (Newton on
        ``x'(s) = 0``, clipped to the bracket)."""
        k = np.arange(1, self.H + 1)
        c, d = X[:, 1::2], X[:, 2::2]
        t = start.copy()
        for _ in range(iterations):
            ks = np.outer(t, k)
            cos, sin = np.cos(ks), np.sin(ks)
            d1 = np.sum(k * (d * cos - c * sin), axis=1)
            d2 = -np.sum(k**2 * (c * cos + d * sin), axis=1)
            step = np.divide(d1, d2, out=np.zeros_like(d1), where=d2 != 0)
            t = np.clip(t - step, start - h, start + h)
            if np.max(np.abs(step)) <= 1e-15 * np.pi:
                break
        ks = np.outer(t, k)
        return X[:, 0] + np.sum(c * np.cos(ks) + d * np.sin(ks), axis=1)

    def time_series(self, X, phases) -> np.ndarray:
        """The states at the phases ``s`` (radians of the base period), (states, len)."""
        s = np.atleast_1d(np.asarray(phases, float))
        k = np.arange(1, self.H + 1)
        B = np.empty((s.size, self.M))
        B[:, 0] = 1.0
        B[:, 1::2] = np.cos(np.outer(s, k))
        B[:, 2::2] = np.sin(np.outer(s, k))
        return X @ B.T
