"""Two exponential integrators for ``x' = L x + N(t, x)``, ``N = f - L x``, written for
``stiff_models.py``'s measurement (not solver methods: that page says why).

- :func:`etdrk4`: Cox and Matthews (2002), "Exponential time differencing for stiff
  systems", their fourth-order ETDRK4, fixed steps; its coefficients ``phi_1 .. phi_3``
  from one matrix exponential of an augmented block matrix (Saad, 1992, "Analysis of some
  Krylov subspace approximations to the matrix exponential operator").
- :func:`lawson`: the integrating factor (Lawson, 1967, "Generalized Runge-Kutta processes
  for stable systems with large Lipschitz constants") in ``L``'s modal coordinates: SciPy's
  DOP853 on ``y = exp(-L s) x``, restarted each period, so its steps are those of Lawson's
  exponential DOP853 with ``L`` integrated exactly.

Both return the states at the ``periods + 1`` period ends and the right-hand-side
evaluations per period.
"""

from __future__ import annotations

import numpy as np

__all__ = ["etdrk4", "lawson", "phi_functions"]


def phi_functions(A: np.ndarray, h: float) -> tuple[np.ndarray, ...]:
    """``exp(hA), phi_1(hA), phi_2(hA), phi_3(hA)``: the first block row of the exponential
    of ``[[hA, I, 0, 0], [0, 0, I, 0], [0, 0, 0, I], [0, 0, 0, 0]]``."""
    from scipy.linalg import expm

    n = A.shape[0]
    Z = np.zeros((4 * n, 4 * n))
    Z[:n, :n] = h * A
    for b in range(3):
        Z[b * n : (b + 1) * n, (b + 1) * n : (b + 2) * n] = np.eye(n)
    E = expm(Z)
    return tuple(E[:n, b * n : (b + 1) * n] for b in range(4))


def etdrk4(f, L, x0, T: float, steps: int, periods: int) -> tuple[np.ndarray, float]:
    """ETDRK4 with ``steps`` fixed steps per period ``T``."""
    h = T / steps
    E, p1, p2, p3 = phi_functions(L, h)
    E2, q1, _, _ = phi_functions(L, h / 2)
    f1, f2, f3 = p1 - 3 * p2 + 4 * p3, p2 - 2 * p3, -p2 + 4 * p3

    def N(t, x):
        return f(t, x) - L @ x

    x, out = x0.copy(), [x0.copy()]
    for k in range(periods):
        for j in range(steps):
            t = k * T + j * h
            nx = N(t, x)
            a = E2 @ x + (h / 2) * (q1 @ nx)
            na = N(t + h / 2, a)
            b = E2 @ x + (h / 2) * (q1 @ na)
            nb = N(t + h / 2, b)
            c = E2 @ a + (h / 2) * (q1 @ (2 * nb - nx))
            nc = N(t + h, c)
            x = E @ x + h * (f1 @ nx + 2 * f2 @ (na + nb) + f3 @ nc)
        out.append(x.copy())
    return np.array(out), 4.0 * steps


def lawson(f, L, x0, T: float, rtol: float, periods: int) -> tuple[np.ndarray, float]:
    """DOP853 (``rtol``, ``atol = rtol / 100``) on ``y = exp(-L s) x``, each period."""
    from scipy.integrate import solve_ivp

    lam, V = np.linalg.eig(L)
    Vi = np.linalg.inv(V)
    x, out, nfev = x0.copy(), [x0.copy()], 0
    for k in range(periods):
        t0 = k * T

        def g(s, y, t0=t0):
            e = np.exp(lam * s)
            xs = (V @ (e * y)).real
            return (Vi @ (f(t0 + s, xs) - L @ xs)) / e

        y0 = (Vi @ x).astype(complex)
        sol = solve_ivp(g, (0, T), y0, "DOP853", rtol=rtol, atol=rtol / 100)
        nfev += sol.nfev
        x = (V @ (np.exp(lam * T) * sol.y[:, -1])).real
        out.append(x)
    return np.array(out), nfev / periods
