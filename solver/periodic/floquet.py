"""Floquet multipliers of a periodic orbit, how it loses stability, and the test functions
that locate bifurcations along a branch.

The monodromy matrix M (the Jacobian of the period map) has the Floquet multipliers as
eigenvalues; the orbit is stable when all lie inside the unit circle, and the critical
multiplier (largest modulus) names how stability is lost: +1 fold (saddle-node), -1
period doubling, a complex pair Neimark-Sacker.  Liouville's formula ``det M =
exp(int_0^{nT} trace J dtau)`` is checked for every orbit, in logarithms
(``|log det M - int trace J|``, about the relative error of det M).

Stability is judged with a tolerance, because a multiplier is only as exact as M.  With
``eps`` the estimated relative error of M -- the larger of the Liouville error and
``1000 rtol`` of the integration (the global-error rule the classification also uses) --
first-order perturbation theory (Wilkinson 1965, "The Algebraic Eigenvalue Problem",
section 2.8) bounds the change of multiplier i by ``kappa_i eps |M|_2``, with
``kappa_i = |y_i| |x_i| / |y_i^H x_i|`` from the left and right eigenvectors; near a
defective multiplier the change grows like ``sqrt(eps)`` instead, so

    ``tol_i = min(kappa_i eps, sqrt(eps)) max(1, |M|_2)``.

The orbit is **unstable** when some ``|mu_i| > 1 + tol_i``, **neutral** (on the unit
circle within the error, as every multiplier of an undamped system whose flow preserves
volume may be) when, short of that, some ``|mu_i| >= 1 - tol_i``, and **stable** otherwise.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.linalg import eig

__all__ = ["KINDS", "Floquet", "floquet", "bifurcation_tests", "multiplier_tests"]

KINDS = ("fold", "period-doubling", "neimark-sacker")
STABILITY = ("stable", "neutral", "unstable")
GLOBAL_ERROR = 1e3  # estimated relative error of M per unit of the integration's rtol


@dataclass(frozen=True)
class Floquet:
    multipliers: np.ndarray
    stable: bool
    critical: complex
    kind: str  # "fold", "period-doubling", "neimark-sacker" (type of the critical multiplier)
    liouville_error: float  # |log|det M| - int trace J|, ~ the relative error of det M
    stability: str = ""  # "stable", "neutral" (on the unit circle within tol), "unstable"
    tolerances: np.ndarray | None = None  # tol_i of each multiplier, in the order of mu
    monodromy_error: float | None = None  # eps: the estimated relative error of M

    @property
    def tolerance(self) -> float | None:
        """The critical multiplier's tolerance on ``|mu|``."""
        return None if self.tolerances is None else float(self.tolerances[0])

    def describe(self) -> dict:
        return {
            "multipliers": [
                {"re": float(m.real), "im": float(m.imag), "abs": float(abs(m))}
                for m in self.multipliers
            ],
            "stable": self.stable,
            "stability": self.stability,
            "tolerance": self.tolerance,
            "tolerances": None if self.tolerances is None else self.tolerances.tolist(),
            "monodromy_error": self.monodromy_error,
            "stability_meaning": "neutral: some |mu| within 1 +- its tolerance, none beyond; "
            "tol_i = min(kappa_i eps, sqrt(eps)) max(1, |M|), eps = max(Liouville error, "
            "1000 rtol)",
            "critical": {
                "re": float(self.critical.real),
                "im": float(self.critical.imag),
                "abs": float(abs(self.critical)),
            },
            "critical_type": self.kind,
            "liouville_error": self.liouville_error,
            "liouville_error_meaning": "|log det M - integral of trace J over the period|; "
            "null when round-off has taken det M (multipliers near zero)",
        }

    to_dict = describe


def floquet(
    M: np.ndarray, trace_integral: float, *, rtol: float = 1e-11, error: float | None = None
) -> Floquet:
    """Multipliers of monodromy ``M``, stability with its tolerance, critical type and
    Liouville's check.

    ``rtol`` is the relative tolerance M was integrated with (default the flow map's);
    ``error`` an independent estimate of M's relative error (for example from
    ``monodromy_agreement``), used when larger than the others.
    """
    mu, left, right = eig(M, left=True, right=True)
    order = np.argsort(-np.abs(mu))
    mu, left, right = mu[order], left[:, order], right[:, order]
    crit = complex(mu[0])
    if abs(crit.imag) > 1e-9 * max(1.0, abs(crit)):
        kind = "neimark-sacker"
    else:
        kind = "fold" if crit.real > 0 else "period-doubling"
    # Compared in logarithms: over long periods det M underflows long before its log does.
    sign, logdet = np.linalg.slogdet(M)
    error_l = abs(logdet - trace_integral) if sign > 0 else math.inf
    eps = max(GLOBAL_ERROR * rtol, error or 0.0)
    if math.isfinite(error_l):
        eps = max(eps, error_l)
    # Condition number of each eigenvalue: |y| |x| / |y^H x| (eig returns unit vectors).
    overlap = np.abs(np.sum(np.conj(left) * right, axis=0))
    kappa = np.where(overlap > 0, 1.0 / np.maximum(overlap, 1e-300), np.inf)
    tol = np.minimum(kappa * eps, math.sqrt(eps)) * max(1.0, float(np.linalg.norm(M, 2)))
    size = np.abs(mu)
    if np.any(size > 1.0 + tol):
        stability = "unstable"
    elif np.any(size >= 1.0 - tol):
        stability = "neutral"
    else:
        stability = "stable"
    return Floquet(
        mu, stability == "stable", crit, kind, float(error_l), stability, tol, float(eps)
    )


def bifurcation_tests(M: np.ndarray) -> np.ndarray:
    """Test functions (fold, period doubling, Neimark-Sacker) and the number of complex
    pairs, which must not change across a Neimark-Sacker point (where a pair merges into
    two real multipliers the product changes sign without any crossing of the circle).

    * ``det(M - I)`` -- fold (a multiplier through +1),
    * ``det(M + I)`` -- period doubling (a multiplier through -1),
    * ``prod over complex pairs (|mu|^2 - 1)`` -- Neimark-Sacker (a pair through the circle).
    """
    eye = np.eye(M.shape[0])
    mu = np.linalg.eigvals(M)
    complex_pairs = [m for m in mu if m.imag > 1e-9]
    ns = float(np.prod([abs(m) ** 2 - 1.0 for m in complex_pairs])) if complex_pairs else 1.0
    return np.array([np.linalg.det(M - eye), np.linalg.det(M + eye), ns, len(complex_pairs)])


def multiplier_tests(mu: np.ndarray) -> np.ndarray:
    """:func:`bifurcation_tests` from the multipliers themselves, for a method that gives
    them without a monodromy matrix (Hill's): ``prod (mu_i - 1)``, ``prod (mu_i + 1)``
    (real, up to round-off, since complex multipliers come in conjugate pairs), the
    Neimark-Sacker product and the number of complex pairs."""
    mu = np.asarray(mu, dtype=complex)
    complex_pairs = [m for m in mu if m.imag > 1e-9]
    ns = float(np.prod([abs(m) ** 2 - 1.0 for m in complex_pairs])) if complex_pairs else 1.0
    fold, pd = np.prod(mu - 1.0).real, np.prod(mu + 1.0).real
    return np.array([float(fold), float(pd), ns, len(complex_pairs)])
