"""Floquet multipliers of a periodic orbit, how it loses stability, and the test functions
that locate bifurcations along a branch.

The monodromy matrix M (the Jacobian of the period map) has the Floquet multipliers as
eigenvalues; the orbit is stable when all lie inside the unit circle, and the critical
multiplier (largest modulus) names how stability is lost: +1 fold (saddle-node), -1
period doubling, a complex pair Neimark-Sacker.  Liouville's formula ``det M =
exp(int_0^{nT} trace J dtau)`` is checked for every orbit, in logarithms
(``|log det M - int trace J|``, about the relative error of det M).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

__all__ = ["KINDS", "Floquet", "floquet", "bifurcation_tests"]

KINDS = ("fold", "period-doubling", "neimark-sacker")


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
            ],
            "stable": self.stable,
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
