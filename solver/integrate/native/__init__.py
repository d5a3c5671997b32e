"""Compiled integration: the generated C right-hand side driven by C integrators.

* ``build.py`` -- compile and cache the library of a generated model;
* ``batch.py`` -- sampled runs of many points (lockstep groups or point by point), and
  ``run_batch``, a spec constructor over the front door ``integrate()`` (``../run.py``);
* ``phase.py`` -- the same in the excitation phase (several forcing frequencies at once);
* ``maps.py`` -- the same engine for maps: Poincare points, extremes at every step, the
  valid range and the exponent's tangent vector, with no Python step per point;
* ``fallback.py`` -- the one NumPy/SciPy fallback without a compiler, for every spec;
* ``native_*.c`` -- the integrators (DOPRI5, DOP853, RK4), whose tableaux come from
  ``../tableau.py``.

:func:`run` is the ``simulate`` back end of the ``native`` family: one point.
"""

from __future__ import annotations

import numpy as np

from ..result import Request, Run
from ..spec import RunSpec
from . import build, fallback
from .batch import NATIVE_METHODS, STATUS, run_batch
from .build import NativeUnavailable, cache_dir, compiler, library, source

__all__ = [
    "NATIVE_METHODS",
    "STATUS",
    "NativeUnavailable",
    "cache_dir",
    "compiler",
    "library",
    "reset",
    "run",
    "run_batch",
    "run_many",
    "source",
]


def reset() -> None:
    """Forget this session's loaded libraries, failed builds and warnings (after changing
    ``GEARSYM_CC`` or the cache, say); libraries cached on disk stay."""
    build._loaded.clear()
    build._paths.clear()
    build._failed.clear()
    build._broken.clear()
    fallback._warned.clear()


def run(system, req: Request) -> Run:
    """One point through ``integrate()``, on its own steps."""
    from ..run import integrate

    res = integrate(system, req.x0, _spec(req, lockstep=False))
    return _as_run(res, 0, req, system)


def run_many(systems, reqs, workers: int = 1) -> list[Run]:
    """Many points of one model with one request each (same options, own ``x0``) in one
    call of the lockstep engine; ``workers`` processes."""
    from ..run import Batch, integrate

    P = np.array([s.p for s in systems])
    X0 = np.array([np.asarray(q.x0, float) for q in reqs])
    res = integrate(Batch.of(systems[0].module, P), X0, _spec(reqs[0]), workers=workers)
    return [_as_run(res, i, q, s) for i, (q, s) in enumerate(zip(reqs, systems, strict=True))]


def _spec(req: Request, lockstep: bool = True) -> RunSpec:
    return RunSpec(
        method=req.method,
        rtol=req.rtol,
        atol=req.atol,
        t0=req.t0,
        transient=req.transient,
        periods=req.periods,
        samples_per_period=req.samples_per_period,
        steps_per_period=req.steps_per_period,
        bound=req.bound,
        valid_range="stop" if req.on_invalid == "error" else "record",
        lockstep=lockstep,
    )


def _as_run(res, i: int, req: Request, system) -> Run:
    # A view (states x samples) of the engine's output: no second copy of a long run.
    x = res.x[i].T
    status = res.status[i]
    nfev, nsteps = int(res.nfev[i]), int(res.nsteps[i])
    exit_ = None
    if res.exits is not None and np.isfinite(res.exits[i, 0]):
        tau, k, value = res.exits[i]
        exit_ = (float(tau), system.states[int(k)], float(value))
    if status in ("ok", "left the valid range"):
        # simulate() turns an exit into status "invalid" when asked to stop there
        return Run(x, "ok", "", nfev, nsteps, None, exit_)
    t_fail = float(res.t_fail[i])
    if status == "divergent":
        message = f"a state passed |x| = {req.bound:g} at tau = {t_fail:.6g}"
        return Run(x, "divergent", message, nfev, nsteps, None, exit_)
    message = f"{req.method} stopped at tau = {t_fail:.6g}: {status}"
    return Run(x, "failed", message, nfev, nsteps, None, exit_)
