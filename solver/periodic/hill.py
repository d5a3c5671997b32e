"""Hill's method for the stability of a harmonic-balance solution.

A perturbation ``y = exp(sigma tau) q(s)`` of the solution, with ``q`` periodic, solves
``(A_hat - (omega/n) D) q = sigma q`` with ``A_hat = P diag(J) E`` (the Toeplitz form of the
Jacobian over the solution), so the eigenvalues of Hill's matrix are the Floquet exponents,
each repeated shifted by ``i k omega / n``.  The physical ones are picked by their
eigenvectors' symmetry (von Groll and Ewins 2001, "The harmonic balance method with
arc-length continuation in rotor/stator contact problems", J. Sound Vib. 241): written
in complex harmonics ``-H..H``, a copy shifted by ``k`` has its weight centred on ``-k``,
so the ``n_states`` exponents whose weight is centred nearest harmonic 0 (distinct
multipliers) are kept; the multipliers are ``exp(sigma n T)``.
"""

from __future__ import annotations

import numpy as np

from .floquet import Floquet, floquet

__all__ = ["HILL_HARMONICS", "hill"]


HILL_HARMONICS = 8


def hill(
    problem, X, p, *, error: float = 0.0, harmonics: int | None = None
) -> tuple[np.ndarray, Floquet]:
    """The physical Floquet exponents of the solution ``X`` by Hill's method (eigenvector
    symmetry, see the module text) and the multipliers ``exp(sigma n T)`` judged as
    :func:`~.floquet.floquet` judges a monodromy's, with ``error`` (the truncation's
    estimate, for example the tail share) as the multipliers' relative error.

    ``harmonics``: the perturbations' harmonics of omega/n (default
    ``min(H, HILL_HARMONICS n)``, as many harmonics of omega whatever n): the physical
    exponents converge much faster in them than the solution does in H (on the reference
    model's period-1 orbits 8 harmonics already agree with the monodromy to 1e-9, on its
    period-2 orbit 16 of omega/2 to 1e-7), and the eigenproblem's cost grows with the
    cube of its size."""
    nx = problem.system.n
    cap = HILL_HARMONICS * problem.n if harmonics is None else harmonics
    H = min(problem.H, cap)
    M = 2 * H + 1
    J = problem._jacobian(problem.times(p), X @ problem.E.T, p)
    A = problem.hill_matrix(X, p, H, J)
    period = 2 * np.pi * problem.n / problem.omega(p)
    # The trace integral that Liouville's check compares det M with, exact on the AFT grid.
    trace_integral = float(np.mean(np.trace(J, axis1=0, axis2=1)) * period)
    sig = _strip(np.linalg.eigvals(A), nx, problem.omega(p) / problem.n, period, trace_integral)
    if sig is None:
        sig = _symmetric(A, nx, M, H, period)
    M_diag = np.diag(np.exp(sig * period))
    return sig, floquet(M_diag, trace_integral, rtol=1e-13, error=error)


def _distinct(order, sigma, nx, period) -> list[int]:
    """The first ``nx`` of ``order`` that are not shifted copies of one already chosen.
    A copy shares the multiplier but sits a multiple of ``i 2 pi / period`` away; an
    exponent of multiplicity two (two identical pinions on identical bearings, say) shares
    the multiplier at the same place, and both are kept."""
    mu = np.exp(sigma * period)
    shift = np.pi / period  # half the spacing of the copies
    chosen: list[int] = []
    for i in order:
        if len(chosen) == nx:
            break
        if not any(
            abs(mu[i] - mu[j]) <= 1e-6 * max(1.0, abs(mu[j])) and abs(sigma[i] - sigma[j]) > shift
            for j in chosen
        ):
            chosen.append(int(i))
    return chosen


def _strip(sigma, nx, w, period, trace_integral):
    """The fast path (eigenvalues only): the copies with |Im sigma| <= w/2, accepted when
    there are exactly ``nx`` distinct ones and their sum passes Liouville's check (a
    spurious eigenvalue of the truncation would fail it); else None."""
    inside = np.flatnonzero(np.abs(sigma.imag) <= 0.5 * w * (1 + 1e-9))
    order = inside[np.argsort(np.abs(sigma.imag[inside]))]
    # exactly nx distinct multipliers in the strip: one more would be a spurious one
    if len(_distinct(order, sigma, nx + 1, period)) != nx:
        return None
    chosen = _distinct(order, sigma, nx, period)
    total = float(np.sum(sigma[chosen].real) * period)
    if abs(total - trace_integral) > 1e-8 * max(1.0, abs(trace_integral)):
        return None
    return sigma[chosen]


def _symmetric(A, nx, M, H, period):
    """The symmetry criterion on the eigenvectors (von Groll and Ewins 2001)."""
    sigma, V = np.linalg.eig(A)
    V = V.reshape(nx, M, -1)
    # complex harmonics -H..H of each eigenvector: c_k cos + s_k sin = ((c_k - i s_k) e^{iks}
    # + (c_k + i s_k) e^{-iks}) / 2
    pos = (V[:, 1::2, :] - 1j * V[:, 2::2, :]) / 2
    neg = (V[:, 1::2, :] + 1j * V[:, 2::2, :]) / 2
    W = np.concatenate(
        [np.abs(neg[:, ::-1, :]) ** 2, np.abs(V[:, :1, :]) ** 2, np.abs(pos) ** 2], axis=1
    ).sum(axis=0)
    k = np.arange(-H, H + 1)
    centre = np.abs((k[:, None] * W).sum(axis=0) / W.sum(axis=0))
    return sigma[_distinct(np.argsort(centre, kind="stable"), sigma, nx, period)]
