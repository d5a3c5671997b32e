"""A continued branch of harmonic-balance solutions (``hb_continuation.py`` makes it):
its points, located events and how it ended, with the statistics a frequency response
plots (mean, half peak-to-peak, RMS, the top harmonics' share)."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..system import System
from .harmonic_balance import HarmonicBalance

__all__ = ["HBBranch", "HBPoint"]


@dataclass(frozen=True)
class HBPoint:
    value: float
    coefficients: np.ndarray  # (states, 2H + 1)
    multipliers: np.ndarray | None
    stable: bool | None
    stability: str | None
    tangent_sign: int  # sign of d(parameter)/d(arclength)


@dataclass(frozen=True)
class HBBranch:
    """A continued branch of harmonic-balance solutions, in the order of arclength, and
    the folds and stability changes located on it."""

    system: System
    parameter: str
    n: int
    harmonics: int
    samples: int
    points: tuple[HBPoint, ...]
    events: tuple[dict, ...] = ()
    wall_time: float = 0.0
    notes: list = field(default_factory=list)
    # how it ended: "complete", "boundary" (the edge of the parameter's valid range),
    # "turned" (a fold took it out at the start's side), "stalled", "max-points"
    status: str = "complete"
    message: str = ""

    @property
    def values(self) -> np.ndarray:
        return np.array([p.value for p in self.points])

    @property
    def stable(self) -> np.ndarray:
        return np.array([bool(p.stable) for p in self.points])

    def _problem(self) -> HarmonicBalance:
        return HarmonicBalance(self.system, self.harmonics, self.n, self.samples)

    def series(self, name: str, points: int = 512) -> np.ndarray:
        """``name`` over one period at every point, (len, points)."""
        i = self.system.index(name)
        s = 2 * np.pi * np.arange(points) / points
        prob = self._problem()
        C = np.array([p.coefficients[i] for p in self.points])
        return prob.time_series(C, s)

    def mean(self, name: str) -> np.ndarray:
        i = self.system.index(name)
        return np.array([p.coefficients[i, 0] for p in self.points])

    def amplitude(self, name: str) -> np.ndarray:
        """Half peak-to-peak of ``name`` at every point."""
        y = self.series(name)
        return (y.max(axis=1) - y.min(axis=1)) / 2

    def maximum(self, name: str) -> np.ndarray:
        return self.series(name).max(axis=1)

    def minimum(self, name: str) -> np.ndarray:
        return self.series(name).min(axis=1)

    def rms(self, name: str) -> np.ndarray:
        i = self.system.index(name)
        C = np.array([p.coefficients[i] for p in self.points])
        return np.sqrt(C[:, 0] ** 2 + 0.5 * np.sum(C[:, 1:] ** 2, axis=1))

    def tail_shares(self, top: int | None = None) -> np.ndarray:
        """Per point, the largest share (RMS sense, over the coordinates) of the response
        that the highest ``top`` harmonics carry (default a quarter of H)."""
        top = top or max(1, self.harmonics // 4)
        out = np.zeros(len(self.points))
        for c in self.system.coordinates:
            i = self.system.index(c)
            C = np.array([p.coefficients[i, 1:] for p in self.points])
            a2 = C[:, 0::2] ** 2 + C[:, 1::2] ** 2
            total = a2.sum(axis=1)
            share = np.sqrt(
                np.divide(
                    a2[:, -top:].sum(axis=1), total, out=np.zeros_like(total), where=total > 0
                )
            )
            out = np.maximum(out, share)
        return out

    def records(self) -> list[dict]:
        """One record per solution point: the parameter under its own name, ``stable``,
        and per coordinate its ``mean``, ``amplitude`` (half peak-to-peak) and ``rms``."""
        coords = self.system.coordinates
        stats = {c: (self.mean(c), self.amplitude(c), self.rms(c)) for c in coords}
        out = []
        for k, p in enumerate(self.points):
            rec = {self.parameter: p.value, "stable": p.stable, "stability": p.stability}
            for c in coords:
                m, a, r = stats[c]
                rec[c] = {"mean": float(m[k]), "amplitude": float(a[k]), "rms": float(r[k])}
            out.append(rec)
        return out
