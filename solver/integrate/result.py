"""What every integration back end takes and returns: one request, one result type."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["Request", "Run", "first_exit"]


@dataclass(frozen=True)
class Request:
    """One integration, as ``simulate`` checked it (``x0`` and ``grid`` are None only
    while the options are being checked).

    The run starts at ``t0`` in state ``x0``; after ``transient`` forcing periods it is
    sampled on ``grid`` (``periods * samples_per_period + 1`` times, the last one closing
    the window).
    """

    x0: np.ndarray
    t0: float
    grid: np.ndarray
    method: str
    rtol: float
    atol: float
    transient: int
    periods: int
    samples_per_period: int
    steps_per_period: int
    max_step: float | None
    bound: float
    on_invalid: str
    transient_rtol: float | None = None  # the transient's own (two_tolerances.py)


@dataclass
class Run:
    """A back end's answer: samples ``x`` (n, len(grid)) and how the run ended.

    ``status`` is ``ok``, ``divergent`` or ``failed``; ``left_valid_range`` is
    ``(tau, coordinate, value)`` of the first exit from the force law's valid range when
    the back end located it (else ``simulate`` looks for it in the samples).
    """

    x: np.ndarray
    status: str
    message: str = ""
    nfev: int = 0
    nsteps: int = 0
    crossings: int | None = None
    left_valid_range: tuple | None = None


def first_exit(system, t, x) -> tuple | None:
    """(tau, coordinate, value) of the first sample outside the force law's valid range
    (``x`` (n, K) at times ``t``), or None."""
    bounds = system.contract.valid_bounds()
    if not bounds:
        return None
    idx = [i for i, _ in bounds]
    a = np.array([b for _, b in bounds])[:, None]
    for k0 in range(0, x.shape[1], 1 << 16):  # blocks: small temporaries on long runs
        out = np.abs(x[idx, k0 : k0 + (1 << 16)]) > a * (1 + 1e-12)
        if np.any(out):
            k = int(np.argmax(np.any(out, axis=0)))
            j = int(np.argmax(out[:, k]))
            return float(t[k0 + k]), system.states[idx[j]], float(x[idx[j], k0 + k])
    return None
