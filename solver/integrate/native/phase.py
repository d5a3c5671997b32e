"""Runs in the excitation phase ``s = omega tau``: points of different forcing frequency in
one lockstep group.

In ``s`` every point's forcing period is ``2 pi``: ``dX/ds = f(s / omega, X) / omega`` with
each point's own ``omega``, so a group of frequencies shares the time grid and the step
(the compiled engine's phase time mode).  The state stays the physical one (coordinates
and their derivatives in ``tau``), so a run at one frequency can start from another's end
state: a frequency sweep with continuation of the state is a chain of such runs.  Without
a compiler the same runs go through the one NumPy/SciPy fallback (``fallback.py``), with
one warning line.
"""

from __future__ import annotations

from ..spec import RunResult, RunSpec

__all__ = ["run_phase"]


def run_phase(module, P, X0, *, samples_per_period: int = 64, **options) -> RunResult:
    """Integrate every point ``P[i]`` (N, P) from ``X0[i]`` (N, n) over ``transient +
    periods`` forcing periods in the phase; ``t`` of the result is the phase ``s`` of the
    samples (``2 pi (transient + k / samples_per_period)``), the same for every point
    (divide by each point's omega for tau). ``options``: other
    :class:`~..spec.RunSpec` fields (the valid range is recorded by default)."""
    from ..run import Batch, integrate

    spec = RunSpec(
        **{"valid_range": "record", **options},
        time="phase",
        samples_per_period=samples_per_period,
    )
    return integrate(Batch.of(module, P), X0, spec)
