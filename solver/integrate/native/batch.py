"""Sampled runs of many parameter points in compiled code, and ``run_batch``.

``run_batch(module, P, X0, ...)`` integrates many parameter points of one generated model:
Dormand-Prince 5(4) (``dopri5``), DOP853 (``dop853``) or classic RK4 (``rk4``), with the
step control of SciPy's RK45/DOP853, sampled ``samples_per_period`` times per forcing
period after a transient (``native_*.c``). It is a spec constructor over the front door,
``integrate()`` (``../run.py``), which checks the inputs once, decides once between the
compiled engine and the NumPy/SciPy fallback (``fallback.py``) and splits the points over
worker processes.

The compiled runs themselves are ``engine.run_compiled``: points either share time and
step size in lockstep groups (the excitation computed once per stage for the group) or
take their own steps.
"""

from __future__ import annotations

from ..spec import RunResult, RunSpec

__all__ = ["NATIVE_METHODS", "STATUS", "run_batch"]

NATIVE_METHODS = ("dopri5", "dop853", "rk4")
_CODES = {"dopri5": 0, "dop853": 1, "rk4": 2}
STATUS = {
    0: "ok",
    1: "divergent",
    2: "too many steps",
    3: "not finite",
    4: "step too small",
    5: "left the valid range",
}


def run_batch(
    module,
    P,
    X0,
    *,
    workers: int = 1,
    fallback: bool = True,
    **options,
) -> RunResult:
    """Integrate every parameter row ``P[i]`` (N, P) from ``X0[i]`` (N, n) of ``module``.

    ``options`` are :class:`~..spec.RunSpec` fields (method, rtol, atol, t0, transient,
    periods, samples_per_period, steps_per_period, bound, max_steps, lockstep, group,
    dense, valid_range); the excitation period is ``T = 2 pi / omega``, the same for all
    points. ``fallback=False`` raises :class:`~.build.NativeUnavailable` without a
    compiler instead of running the NumPy/SciPy fallback; ``workers`` processes.
    """
    from ..run import Batch, integrate

    spec = RunSpec(**{"valid_range": "ignore", **options})
    backend = "auto" if fallback else "native"
    return integrate(Batch.of(module, P), X0, spec, backend=backend, workers=workers)
