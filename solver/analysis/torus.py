"""Evidence that a Poincare sequence lies on an invariant circle of a two-frequency torus.

On a torus with base frequencies f1 = 1/T and f2, the stroboscopic section (one point per
forcing period T) is an invariant circle on which the points turn by rho = f2 T (mod 1),
so each coordinate's series holds only the lines m rho (mod 1, folded into [0, 1/2]), and
rho is irrational. A pure function of the points tests both.

References: J. Laskar, "Frequency analysis for multi-dimensional systems. Global dynamics
and diffusion", Physica D 67 (1993) 257-281 (NAFF, the frequency maximising the
Hann-windowed Fourier sum); E. Grandke, "Interpolation algorithms for discrete Fourier
transforms of weighted signals", IEEE Trans. Instrum. Meas. 32 (1983) 350-355.
"""

from __future__ import annotations

from dataclasses import dataclass, fields
from typing import NamedTuple

import numpy as np

from .spectra import _hann  # the one periodic Hann window (cached), with its sum

__all__ = ["MIN_SHARE", "Peak", "TorusEvidence", "torus_evidence"]

MIN_SAMPLES = 100
# significant lines: the 20 largest maxima above 1 % of the largest; harmonics m = 1..12
FLOOR, MAX_PEAKS, MAX_ORDER = 0.01, 20, 12
MIN_SHARE = 0.9
"""Share of the power the harmonics m rho must explain. An analytic invariant circle's
Fourier coefficients decay exponentially in m, so |m| <= 12 hold nearly all of it (the
tests' distorted circles: above 0.999); the 10 % left is room for window leakage and a
weak transient. Chaos spreads its power over a band (logistic map, r = 4: about 1 %)."""


class Peak(NamedTuple):
    """One significant line of one coordinate; see :class:`TorusEvidence`."""

    frequency: float
    amplitude: float
    m: int | None
    coordinate: int


@dataclass(frozen=True)
class TorusEvidence:
    """What the refined spectrum of a Poincare sequence says about an invariant circle.

    Attributes
    ----------
    rotation_number : float
        rho, cycles per forcing period, in (0, 1/2].
    nearest_rational : tuple of (int, int, float)
        (p, q, |rho - p/q|), the nearest p/q with 1 <= q <= max_denominator.
    tolerance, incommensurate : float, bool
        tol = max(tolerance_bins / K, |halves[0] - halves[1]|); |rho - p/q| > tol (all q).
    explained_share : float
        Share of the mean-removed variance (coordinates scaled to unit variance, then
        averaged) in lines explained as harmonics m rho; in [0, 1].
    peaks : tuple of Peak
        Every coordinate's significant lines: ``frequency`` (cycles per forcing period,
        in [0, 1/2]), ``amplitude`` (coordinate's unit; ``a cos(2 pi f k)`` reads ``a``),
        ``m`` (lowest order with m rho, mod 1 and folded, within 1/K; None if none),
        ``coordinate`` (the row of ``points``).
    halves : tuple of float
        rho refined on the first and on the second half of the record.
    samples, period : int, float
        K points; T, the forcing period in the caller's unit of time.
    """

    rotation_number: float
    nearest_rational: tuple[int, int, float]
    tolerance: float
    incommensurate: bool
    explained_share: float
    peaks: tuple[Peak, ...]
    halves: tuple[float, float]
    samples: int
    period: float = 1.0
    min_share: float = MIN_SHARE

    @property
    def is_torus(self) -> bool:
        """Incommensurate rho and explained share at least ``min_share`` (0.9)."""
        return bool(self.incommensurate and self.explained_share >= self.min_share)

    @property
    def base_frequencies(self) -> tuple[float, float]:
        """(f1, f2) = (1/T, rho/T), cycles per unit time."""
        return (1.0 / self.period, self.rotation_number / self.period)

    def describe(self) -> dict:
        """A JSON-able summary (frequencies per forcing period, f1 and f2 per unit time)."""
        out = {f.name: getattr(self, f.name) for f in fields(self)}
        p, q, distance = self.nearest_rational
        out.update(
            test="refined frequency analysis (Hann window, NAFF refinement of rho)",
            is_torus=self.is_torus,
            base_frequencies=list(self.base_frequencies),
            nearest_rational={"p": p, "q": q, "distance": distance},
            halves=list(self.halves),
            peaks=[pk._asdict() for pk in self.peaks],
        )
        return out

    to_dict = describe


def _checked(points: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The varying rows, their standard deviations, and them mean-removed and scaled."""
    X = np.atleast_2d(np.asarray(points, dtype=float))
    if X.ndim != 2 or X.shape[1] < MIN_SAMPLES:
        raise ValueError(
            f"torus_evidence: points have shape {np.shape(points)}; pass (d, K), one row per "
            f"coordinate, one column per forcing period, K >= {MIN_SAMPLES}"
        )
    if not np.all(np.isfinite(X)):
        raise ValueError("torus_evidence: points hold nan or inf; pass finite points")
    scale = np.maximum(1.0, np.max(np.abs(X), axis=1))
    rows = np.nonzero(np.ptp(X, axis=1) > 1e-12 * scale)[0]
    if rows.size == 0:
        raise ValueError(
            "torus_evidence: every coordinate is constant (a fixed point of the section): "
            "use the periodicity test"
        )
    Y = X[rows] - X[rows].mean(axis=1, keepdims=True)
    return rows, Y.std(axis=1), Y / Y.std(axis=1, keepdims=True)


def _line_peaks(y: np.ndarray) -> list[tuple[float, float, float]]:
    """Significant lines of one unit-variance series: (frequency, amplitude, power).

    The ``MAX_PEAKS`` largest local maxima of the Hann spectrum above ``FLOOR`` times the
    largest, refined by Grandke's interpolation: alpha = |X_(k+-1)| / |X_k| (the larger
    neighbour), delta = +-(2 alpha - 1)/(alpha + 1), f = (k + delta)/K, amplitude
    a = 2 |X_k| (1 - delta^2) / (S sinc delta), S the window's sum; power a^2/2 (a bin at
    the Nyquist frequency is its own mirror: a = |X_k| / S, power a^2).
    """
    K = y.size
    w, S = _hann(K)
    a = np.abs(np.fft.rfft(y * w))
    # bin 1 ignores bin 0 (the window's leakage of the removed mean)
    left = np.r_[np.inf, 0.0, a[1:-1]]
    right = np.r_[a[1:], a[-2] if K % 2 == 0 else 0.0]
    k = np.nonzero((a >= left) & (a >= right))[0]
    k = k[(k > 0) & (a[k] >= FLOOR * a[1:].max())]
    k = k[np.argsort(a[k])[::-1][:MAX_PEAKS]]
    side = np.where(right[k] >= left[k], 1.0, -1.0)
    alpha = np.maximum(right[k], left[k]) / a[k]
    delta = side * (2 * alpha - 1) / (alpha + 1)
    amp = 2 * a[k] * (1 - delta**2) / (S * np.sinc(delta))
    f = np.clip((k + delta) / K, 0.0, 0.5)
    nyquist = 2 * k == K
    f[nyquist], amp[nyquist] = 0.5, a[k[nyquist]] / S
    power = np.where(nyquist, amp**2, amp**2 / 2)
    return [(float(x), float(y), float(z)) for x, y, z in zip(f, amp, power, strict=True)]


def _naff(Y: np.ndarray, guess: float, half_width: float) -> float:
    """Laskar's refinement: the f in [guess -+ half_width] within [0, 1/2] that maximises
    sum over rows |sum_k w_k y_k exp(-2 pi i f k)|^2, w the Hann window."""
    K = Y.shape[1]
    V, k = Y * _hann(K)[0], np.arange(K)

    def minus_power(f: float) -> float:
        return -float(np.sum(np.abs(V @ np.exp(-2j * np.pi * f * k)) ** 2))

    bounds = (max(guess - half_width, 0.0), min(guess + half_width, 0.5))
    options = {"xatol": 1e-6 / K}
    from scipy.optimize import minimize_scalar  # here: importing it costs 0.8 s a command

    return float(minimize_scalar(minus_power, bounds=bounds, method="bounded", options=options).x)


def _explain(lines, rho: float, K: int) -> tuple[list, float]:
    """Harmonic order of each line (the lowest m with m rho, mod 1 and folded, within one
    bin 1/K), its amplitude in the coordinate's unit, and the explained share of unit
    variance averaged over the rows."""
    m_rho = rho * np.arange(1, MAX_ORDER + 1)
    harmonics = np.abs(m_rho - np.round(m_rho))
    tagged, share = [], 0.0
    for row, std, row_lines in lines:
        explained = 0.0
        for f, amp, power in row_lines:
            hit = np.nonzero(np.abs(harmonics - f) <= 1.0 / K)[0]
            m = int(hit[0]) + 1 if hit.size else None
            explained += power if m is not None else 0.0
            tagged.append((f, amp * std, m, row))
        share += min(explained, 1.0)
    return tagged, share / len(lines)


def torus_evidence(
    points: np.ndarray,
    *,
    period: float = 1.0,
    max_denominator: int = 32,
    tolerance_bins: float = 0.1,
    min_share: float = MIN_SHARE,
) -> TorusEvidence:
    """Is a Poincare sequence an invariant circle of a two-frequency torus?

    Each row, mean removed and scaled to unit variance, gets a Hann spectrum whose
    significant lines are refined by Grandke's interpolation. The three strongest lines
    are candidates for rho, each refined by NAFF (the maximum of the summed windowed
    Fourier power within one bin); the one whose harmonics m rho (|f - fold(m rho)| <=
    1/K, m = 1..12) explain the most power is the rotation number. rho is incommensurate
    if |rho - p/q| > tol for every q <= ``max_denominator`` (32, the periodicity test's
    largest period), with tol = max(``tolerance_bins`` / K, |rho_a - rho_b|), rho_a and
    rho_b refined on the two halves of the record (their disagreement measures the
    estimate's error). With |rho - p/q| K < 0.1 (the default) the record's phase drifts
    by less than a tenth of a cycle against the resonance: a period-q orbit with a slow
    transient explains it as well, so it is no evidence of a torus until a longer record.

    Parameters
    ----------
    points : ndarray, shape (d, K) or (K,)
        The section's points, one column per forcing period, K >= 100 (1,000 or more to
        tell rho from the rationals of denominator up to 32, about 1e-3 apart). Each row
        counts equally in the share: leave out rows that carry only integration noise.
    period : float, optional
        T, the forcing period (any unit of time), for ``base_frequencies`` only.
    max_denominator, tolerance_bins, min_share : optional
        As described above and in :class:`TorusEvidence`.

    Returns
    -------
    TorusEvidence

    Raises
    ------
    ValueError
        Points not (d, K) with K >= 100, not finite, or constant in every row; an option
        out of range.
    """
    if not (period > 0 and max_denominator >= 1 and tolerance_bins >= 0):
        raise ValueError(
            f"torus_evidence: period = {period}, max_denominator = {max_denominator}, "
            f"tolerance_bins = {tolerance_bins}; need T > 0, q >= 1 and bins >= 0"
        )
    rows, std, Y = _checked(points)
    K = Y.shape[1]
    lines = [(int(r), float(s), _line_peaks(y)) for r, s, y in zip(rows, std, Y, strict=True)]
    candidates: list[float] = []
    for f, *_ in sorted((ln for *_, row in lines for ln in row), key=lambda ln: -ln[2]):
        if len(candidates) < 3 and all(abs(f - g) > 2.0 / K for g in candidates):
            candidates.append(f)
    trials = []
    for f in candidates:
        rho = _naff(Y, f, 1.0 / K)
        trials.append((rho, *_explain(lines, rho, K)))
    # the most power explained; max() keeps the first (strongest line) of equal shares
    rho, tagged, share = max(trials, key=lambda t: round(t[2], 12))
    h = K // 2
    halves = (_naff(Y[:, :h], rho, 2.0 / K), _naff(Y[:, h : 2 * h], rho, 2.0 / K))
    tol = max(tolerance_bins / K, abs(halves[0] - halves[1]))
    # the nearest p/q, q <= max_denominator (argmin: the smallest q of equal distances)
    q = np.arange(1, max_denominator + 1)
    p = np.round(rho * q)
    i = int(np.argmin(np.abs(rho - p / q)))
    nearest = (int(p[i]), int(q[i]), float(abs(rho - p[i] / q[i])))
    return TorusEvidence(
        rotation_number=rho,
        nearest_rational=nearest,
        tolerance=float(tol),
        incommensurate=nearest[2] > tol,
        explained_share=share,
        peaks=tuple(Peak(*t) for t in tagged),
        halves=halves,
        samples=K,
        period=float(period),
        min_share=float(min_share),
    )
