"""Post-processing of a sampled response: spectra and extremes (the meshing states,
read from the sign of the model's force, are in ``meshing.py``; re-exported here).

All frequencies are non-dimensional angular frequencies (rad per unit of tau), the units
in which the reference study quotes its spectral peaks (0.5 and 1.0 for omega = 0.5);
each peak is also given as a multiple of the excitation frequency omega.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np

from ..integrate import Trajectory
from .meshing import meshing_states

__all__ = ["Spectrum", "extremes", "meshing_states", "spectrum"]


@dataclass(frozen=True)
class Spectrum:
    """One-sided amplitude spectrum of a coordinate over the sampled window.

    ``amplitude`` is scaled so that a pure ``a cos(w t)`` at a bin frequency reads ``a``
    (Hann window, coherent-gain corrected); ``resolution`` is the bin spacing in rad per
    unit tau.
    """

    amplitude: np.ndarray
    omega: float
    window: str
    samples: int
    duration: float
    level: float = 0.0  # the signal's size, at least 1 (its rounding sets a floor)

    @property
    def resolution(self) -> float:
        return 2 * np.pi / self.duration

    @property
    def frequency(self) -> np.ndarray:
        """The bins' frequencies (made on demand: a long run's would be as big as its
        amplitudes)."""
        return np.arange(self.amplitude.size) * self.resolution

    def peaks(self, count: int = 5, floor: float = 1e-3) -> list[dict]:
        """Largest local maxima above ``floor`` times the highest one and above
        :data:`ROUNDING` times the signal's size (``level``): a signal constant to rounding
        (a body at rest, a loop carrying only its locked-in load) has no peaks, where the
        relative floor alone called its rounding noise peaks."""
        a = self.amplitude
        if a.size < 3 or not np.any(a > ROUNDING * self.level):
            return []
        inner = (a[1:-1] >= a[:-2]) & (a[1:-1] >= a[2:])
        idx = np.nonzero(inner)[0] + 1
        idx = idx[(a[idx] >= floor * a.max()) & (a[idx] > ROUNDING * self.level)]
        idx = idx[np.argsort(a[idx])[::-1][:count]]
        return [
            {
                "frequency": float(k * self.resolution),
                "per_omega": float(k * self.resolution / self.omega),
                "amplitude": float(a[k]),
            }
            for k in sorted(idx)
        ]

    def describe(self) -> dict:
        return {
            "window": self.window,
            "samples": self.samples,
            "duration_tau": self.duration,
            "resolution": self.resolution,
            "units": "rad per unit tau; per_omega = frequency / omega",
            "peaks": self.peaks(),
        }

    to_dict = describe


@functools.lru_cache(maxsize=8)
def _hann(n: int) -> tuple[np.ndarray, float]:
    """The periodic Hann window of ``n`` samples (exact on bins) and its sum; a sweep's
    points share one length."""
    w = 0.5 - 0.5 * np.cos(2 * np.pi * np.arange(n) / n)
    w.setflags(write=False)
    return w, float(w.sum())


def spectrum(tr: Trajectory, state: str) -> Spectrum:
    """Hann-windowed FFT of ``state`` over the sampled window (mean removed); non-finite
    samples (a divergent run) give an empty spectrum."""
    y = tr.coordinate(state)
    dt = tr.period / tr.samples_per_period
    if not np.all(np.isfinite(y)):
        return Spectrum(np.zeros(0), tr.system.omega, "hann", 0, y.size * dt)
    n = y.size
    z = y - y.mean()
    if n <= _CACHED:  # a sweep's points share one cached window
        w, w_sum = _hann(n)
        z *= w
    else:  # a long run's window is applied block by block: no second signal-sized array
        for k0 in range(0, n, _CACHED):
            k = np.arange(k0, min(k0 + _CACHED, n))
            z[k0 : k0 + k.size] *= 0.5 - 0.5 * np.cos(2 * np.pi * k / n)
        w_sum = n / 2.0  # the periodic Hann window's sum
    amp = np.abs(np.fft.rfft(z))
    amp *= 2.0 / w_sum
    # the signal's size, never below the states' unit (half backlashes, O(1)): a
    # coordinate at rest near zero (a free body inside its backlash) is noise of the
    # integrator's absolute tolerance, not lines
    level = max(float(np.max(np.abs(y))), 1.0)
    return Spectrum(amp, tr.system.omega, "hann", n, n * dt, level)


_CACHED = 1 << 20
# an amplitude below this share of the signal's size is taken for rounding, not motion:
# far above double precision's (1e-16) and below the accuracy of the runs that make
# spectra (rtol 1e-8 by default); a run at rtol 1e-12 resolves lines of 1e-11 of the
# signal, which this leaves out
ROUNDING = 1e-10


def extremes(tr: Trajectory) -> dict:
    """Max and min of every state over the sampled window."""
    out = {}
    for k, s in enumerate(tr.system.states):
        finite = tr.x[k][np.isfinite(tr.x[k])]
        out[s] = {
            "max": float(finite.max()) if finite.size else None,
            "min": float(finite.min()) if finite.size else None,
        }
    return out
