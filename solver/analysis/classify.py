"""Motion type per coordinate, with the evidence.

Three pieces of evidence are weighed:

1. **Poincare points** (the coordinate and its velocity, one point per forcing period):
   period-n for the smallest n <= 32 with ``|P_{k+n} - P_k| <= tol`` for all k, where
   ``tol`` follows the integrator's tolerance (``max(1e-6, 1e3 rtol)`` times the size
   of the point cloud, at least 1e-3 of it for fixed-step methods).
2. **The largest Lyapunov exponent** of the whole system (variational equations): > 0
   chaotic, ~ 0 quasi-periodic, < 0 periodic.  "~ 0" is judged against its stated
   uncertainty (``lyapunov.uncertainty``), never finer than a growth of e^0.02 per period.
3. **The correlation dimension** of the Poincare set (Grassberger and Procaccia 1983,
   "Characterization of strange attractors", PRL 50): ~ 0 for a finite set of points, ~ 1
   for the closed curve a two-frequency torus leaves (0.85 to 1.15 is read as a curve),
   larger for a strange attractor.  Used when no exponent is available, and as a
   cross-check.  Alone it is weak: Henon's attractor has 1.21.

When the evidence disagrees the verdict is ``undetermined`` and says why.

The evidence always holds the extent (max - min) of the Poincare cloud in the coordinate
and in its velocity (``poincare_extent``): a coordinate slaved to a chaotic one inherits
its verdict, but a cloud of extent 1e-4 half backlashes is a different thing from one of
extent 1, and a reader weighs "quasi-periodic" or "chaotic" against it.  The correlation
dimension needs points: with fewer than ``DIMENSION_POINTS`` (400) the evidence says so
(``sample_limit``); ``analyse_point`` extends the sample to that size before deciding a
non-periodic verdict.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .lyapunov import LyapunovEstimate

__all__ = [
    "DIMENSION_POINTS",
    "Classification",
    "classify_points",
    "correlation_dimension",
    "extent",
    "periodicity",
]

MAX_PERIOD = 32
CURVE = (0.85, 1.15)  # correlation dimensions read as a closed curve
DIMENSION_POINTS = 400  # fewer points: the correlation dimension is stated as limited


@dataclass(frozen=True)
class Classification:
    motion: str  # "period-n", "quasi-periodic", "chaotic", "divergent", "undetermined"
    period: int | None
    evidence: dict = field(default_factory=dict)

    def describe(self) -> dict:
        return {"motion": self.motion, "period": self.period, "evidence": self.evidence}

    to_dict = describe


def periodicity(points: np.ndarray, tol: float) -> int | None:
    """Smallest n <= 32 with every point repeating after n periods, or None.

    ``points`` has shape (d, K): K successive Poincare points.
    """
    K = points.shape[1]
    for n in range(1, min(MAX_PERIOD, K // 2) + 1):
        gap = np.max(np.linalg.norm(points[:, n:] - points[:, :-n], axis=0))
        if gap <= tol:
            return n
    return None


# Pair distances grow with the square of the points: the dimension is estimated on at most
# this many, evenly spread over the run (2,000 points: 2 million pairs, 16 MB), so memory
# stays bounded whatever the number of sampled periods.
DIMENSION_SAMPLE_MAX = 2000


def correlation_dimension(points: np.ndarray) -> float | None:
    """Grassberger-Procaccia slope of log C(r) against log r over the middle of the
    pair-distance distribution (points scaled to unit size), on at most
    :data:`DIMENSION_SAMPLE_MAX` points taken at even strides.  None if degenerate."""
    from scipy.spatial.distance import pdist

    K = points.shape[1]
    if K > DIMENSION_SAMPLE_MAX:
        points = points[:, np.linspace(0, K - 1, DIMENSION_SAMPLE_MAX).astype(int)]
    P = points / max(np.ptp(points, axis=1).max(), 1e-300)
    K = P.shape[1]
    if K < 20:
        return None
    d = pdist(P.T)
    d = np.sort(d[d > 0])
    if d.size < 50:
        return 0.0
    r = np.quantile(d, [0.02, 0.15])
    if r[1] <= r[0] * 1.0001:
        return 0.0
    radii = np.geomspace(r[0], r[1], 8)
    C = np.searchsorted(d, radii) / d.size
    slope = np.polyfit(np.log(radii), np.log(C), 1)[0]
    return float(slope)


def extent(points: np.ndarray) -> dict:
    """Max - min of the Poincare points (d, K) in the coordinate and in its velocity."""
    if points.shape[1] == 0:
        return {"displacement": None, "velocity": None}
    ptp = np.ptp(points, axis=1)
    return {"displacement": float(ptp[0]), "velocity": float(ptp[1]) if ptp.size > 1 else None}


def distinct_points(points: np.ndarray, tol: float) -> int:
    """Number of clusters of points closer than ``tol`` (greedy; enough to tell a finite
    set of points from a curve or a cloud), among the last :data:`DIMENSION_SAMPLE_MAX`."""
    # the last DIMENSION_SAMPLE_MAX consecutive points: a window of a period-n orbit
    # holds all its n points, and the count stays linear in the run's length
    points = points[:, -DIMENSION_SAMPLE_MAX:]
    limit = points.shape[1] // 2
    centres = np.empty((points.shape[0], 0))
    for p in points.T:
        if centres.shape[1] == 0 or np.min(np.linalg.norm(centres - p[:, None], axis=0)) > tol:
            centres = np.column_stack([centres, p])
            if centres.shape[1] > limit:
                break
    return centres.shape[1]


def classify_points(
    points: np.ndarray,
    *,
    tol: float,
    lyapunov: LyapunovEstimate | None = None,
    divergent: bool = False,
    spectrum_peaks: list | None = None,
    period: float | None = None,
) -> Classification:
    """Classify from Poincare points (d, K), an optional exponent and spectral peaks.

    ``period`` is the forcing period T: the exponent counts as positive when the growth
    per period exceeds ``exp(0.02)`` and three times the estimate's own finite-time
    spread.
    """
    evidence: dict = {"poincare_points": int(points.shape[1])}
    if spectrum_peaks is not None:
        evidence["spectrum_peaks"] = spectrum_peaks
    if divergent or not np.all(np.isfinite(points)):
        return Classification("divergent", None, evidence)
    evidence["poincare_extent"] = extent(points)
    # Relative to the cloud's size, but never finer than `tol` in absolute terms: the
    # coordinates are in half backlashes, O(1).
    scale = max(float(np.ptp(points, axis=1).max()), 1.0)
    evidence["tolerance"] = tol * scale
    n = periodicity(points, tol * scale)
    evidence["period_found"] = n
    dim = None if n is not None else correlation_dimension(points)
    evidence["correlation_dimension"] = dim
    lam = None
    if lyapunov is not None:
        evidence["lyapunov"] = lyapunov.describe()
        floor = 0.02 / period if period else 2e-3
        margin = max(floor, lyapunov.uncertainty)
        lam = (
            "positive"
            if lyapunov.exponent > margin
            else ("negative" if lyapunov.exponent < -margin else "zero")
        )
        evidence["lyapunov_sign"] = lam
        evidence["lyapunov_margin"] = margin
    if n is not None:
        if lam == "positive":
            evidence["why"] = "points repeat, yet the exponent is positive"
            return Classification("undetermined", None, evidence)
        return Classification(f"period-{n}", n, evidence)
    clusters = distinct_points(points, tol * scale)
    if clusters <= min(points.shape[1], DIMENSION_SAMPLE_MAX) // 2:
        evidence["distinct_points"] = clusters
        evidence["why"] = (
            f"a finite set of {clusters} points: a period above {MAX_PERIOD}, or not settled"
        )
        return Classification("undetermined", None, evidence)
    if points.shape[1] < DIMENSION_POINTS:
        evidence["sample_limit"] = (
            f"correlation dimension from {points.shape[1]} Poincare points; below "
            f"{DIMENSION_POINTS} it is noisy and biased low, so a curve and a strange "
            "attractor are told apart mainly by the exponent"
        )
    # A torus section is a closed curve, dimension 1; the window is narrow because strange
    # attractors can sit close to it (Henon's map: 1.21).
    curve = dim is not None and CURVE[0] <= dim <= CURVE[1]
    if lam == "positive":
        if dim is not None and dim < 0.5:
            evidence["why"] = "positive exponent but the points form a finite set"
            return Classification("undetermined", None, evidence)
        return Classification("chaotic", None, evidence)
    if lam == "zero" or (lam is None and curve):
        if not curve:
            evidence["why"] = (
                "zero exponent, but the points do not lie on a curve (correlation dimension "
                f"{'unknown' if dim is None else f'{dim:.2f}'}, expected {CURVE[0]} to {CURVE[1]})"
            )
            return Classification("undetermined", None, evidence)
        return Classification("quasi-periodic", None, evidence)
    if lam is None and dim is not None and dim > CURVE[1]:
        return Classification("chaotic", None, evidence)
    evidence["why"] = (
        "no repetition within 32 periods, yet the exponent is negative (not settled, or a "
        "longer period)"
        if lam == "negative"
        else "the evidence is inconclusive"
    )
    return Classification("undetermined", None, evidence)
