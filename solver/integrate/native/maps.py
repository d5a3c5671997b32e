"""The compiled map engine: many points, stroboscopic samples, extremes and the exponent.

A :class:`~..spec.RunSpec` that collects the extremes or the exponent runs in lockstep
groups (``engine.run_compiled``, ``gs_integrate`` in ``native_*.c``) and keeps, without a
Python step per point:

* the Poincare points ``x(t0 + k T)`` of the last ``periods + 1`` periods;
* the extremes of every state over that window, taken at every accepted step and every
  stop (so within the step size of the true extremes, not only at the samples);
* the force law's valid range (the contract's ``valid_range``) as a status, checked at
  every accepted step;
* with ``"exponent"`` collected, the running largest Lyapunov exponent: the variational
  library integrates a tangent vector beside the state from the start, renormalised every
  period (Benettin, Galgani, Giorgilli and Strelcyn 1980, "Lyapunov characteristic
  exponents for smooth dynamical systems", Meccanica 15); ``log |w|`` is summed over the
  last ``lyapunov_periods`` periods of the run, so the first periods align the vector.

Callers go through the front door, ``integrate()`` (``../run.py``), which decides once
between this engine and the NumPy/SciPy fallback (``fallback.py``: the same fields with
the same meaning, some 300 times slower).
"""

from __future__ import annotations

from ..spec import RunSpec

__all__ = ["map_backend"]


def map_backend(module, lyapunov: bool) -> str:
    """The backend of a map run: "native" when the library of ``module`` (with the
    tangent vector's variational system when ``lyapunov``) compiles or is cached, else
    "numpy" after the one warning line (``run.decide_backend``).  The library checked
    is the one-point library the runs of a sweep use (``build.single_point``)."""
    from ..run import decide_backend
    from .build import single_point

    collect = ("samples", "exponent") if lyapunov else ("samples",)
    spec = RunSpec(collect=collect, lyapunov_periods=int(lyapunov))
    return decide_backend(module, spec, shared=single_point(module))
