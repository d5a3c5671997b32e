"""Map runs in native code: many points, stroboscopic samples, extremes and the exponent.

``run_map(module, P, X0, ...)`` integrates every point ``P[i]`` from ``X0[i]`` in lockstep
groups (the engine of ``gs_run_lockstep`` in ``_native.c``) and keeps, without a Python
step per point:

* the Poincare points ``x(t0 + k T)`` of the last ``periods + 1`` periods;
* the extremes of every state over that window, taken at every accepted step and every
  stop (so within the step size of the true extremes, not only at the samples);
* the force law's valid range (the contract's ``valid_range``) as a status, checked at
  every accepted step;
* with ``lyapunov_periods > 0`` the running largest Lyapunov exponent: the variational
  library integrates a tangent vector beside the state from the start, renormalised every
  period (Benettin, Galgani, Giorgilli and Strelcyn 1980, "Lyapunov characteristic
  exponents for smooth dynamical systems", Meccanica 15); ``log |w|`` is summed over the
  last ``lyapunov_periods`` periods of the run, so the first periods align the vector.

Without a working compiler (``backend="auto"``) the same runs go through SciPy's
integrators point by point (``fallback.py``: the same fields with the same meaning,
some 300 times slower), with one warning line; ``backend="native"`` raises
:class:`~.build.NativeUnavailable` instead.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from ...contract import Contract, load_generated
from .batch import _CODES, STATUS, fallback_warning
from .build import NativeUnavailable, library
from .fallback import numpy_map

__all__ = ["MAP_BACKENDS", "MAP_STATUS", "MapRun", "map_backend", "run_map"]

MAP_BACKENDS = ("auto", "native", "numpy")

MAP_STATUS = {**STATUS, 5: "left the valid range"}


@dataclass(frozen=True)
class MapRun:
    """What a map keeps of N runs: ``poincare`` (N, periods + 1, n), ``xmin``/``xmax``
    (N, n), ``lyapunov`` (N, L) running exponent or None, per-run work and status; the
    final state of run i is ``poincare[i, -1]``; ``backend``: "native" or "numpy"."""

    poincare: np.ndarray
    xmin: np.ndarray
    xmax: np.ndarray
    lyapunov: np.ndarray | None
    nfev: np.ndarray
    nsteps: np.ndarray
    status: tuple[str, ...]
    t_fail: np.ndarray
    wall_time: float
    backend: str = "native"


def _tangent(n: int, seed: int) -> np.ndarray:
    v = np.random.default_rng(seed).standard_normal(n)
    return v / np.linalg.norm(v)


def map_backend(module, lyapunov: bool) -> str:
    """The backend of a map run: "native" when the library of ``module`` (with the
    tangent vector's variational system when ``lyapunov``) compiles or is cached, else
    "numpy" after the one warning line.  The map layer asks once in the parent process,
    so workers neither compile nor warn again."""
    try:
        library(module, variational=lyapunov)
    except NativeUnavailable as err:
        fallback_warning(err)
        return "numpy"
    return "native"


def run_map(
    module,
    P,
    X0,
    *,
    method: str = "dop853",
    rtol: float = 1e-8,
    atol: float = 1e-10,
    transient: int = 300,
    periods: int = 100,
    lyapunov_periods: int = 200,
    bound: float = 1e3,
    max_steps: int = 50_000_000,
    group: int = 64,
    seed: int = 0,
    workers: int = 1,
    backend: str = "auto",
) -> MapRun:
    """Integrate ``P`` (N, P) from ``X0`` (N, n) over ``transient + periods`` forcing
    periods ``T = 2 pi / omega``; see the module text for what is kept.  ``workers`` > 1
    splits the points over as many processes.  ``backend``: "native" (the compiled
    engine), "numpy" (SciPy, ``fallback.py``) or "auto" (native when it builds)."""
    if method not in ("dopri5", "dop853"):
        raise ValueError(f"maps run with 'dopri5' or 'dop853', got {method!r}")
    if backend not in MAP_BACKENDS:
        raise ValueError(f"unknown map backend {backend!r}; backends: {', '.join(MAP_BACKENDS)}")
    P = np.ascontiguousarray(np.atleast_2d(np.asarray(P, dtype=float)))
    X0 = np.ascontiguousarray(np.atleast_2d(np.asarray(X0, dtype=float)))
    contract = Contract.of(module)
    n = len(contract.states)
    if P.shape[1] != len(contract.parameters) or X0.shape != (P.shape[0], n):
        raise ValueError(f"P must be (N, {len(contract.parameters)}) and X0 (N, {n})")
    if not (np.all(np.isfinite(P)) and np.all(np.isfinite(X0))):
        raise ValueError("every parameter and initial state must be a finite number")
    omega = P[:, contract.parameters.index(contract.forcing_frequency)]
    if not np.all(omega > 0) or np.ptp(omega) != 0.0:
        raise ValueError(f"{contract.forcing_frequency} must be positive and the same everywhere")
    if not 0 <= lyapunov_periods <= transient + periods:
        raise ValueError(
            f"lyapunov_periods must be in [0, transient + periods = {transient + periods}]"
        )
    opts = dict(
        method=method,
        rtol=rtol,
        atol=atol,
        transient=transient,
        periods=periods,
        lyapunov_periods=lyapunov_periods,
        bound=bound,
        max_steps=max_steps,
        group=1 if contract.piecewise else group,
        seed=seed,
    )
    started = time.perf_counter()
    tangent = lyapunov_periods > 0
    if backend == "auto":  # compile here once, not in every worker
        backend = map_backend(module, tangent)
    elif backend == "native":
        library(module, variational=tangent)
    opts["backend"] = backend
    N = P.shape[0]
    if workers > 1 and N > 1:
        from ...sweep.executor import map_tasks

        chunks = [c for c in np.array_split(np.arange(N), workers) if c.size]
        tasks = [(module.__file__, P[c], X0[c], opts) for c in chunks]
        parts = map_tasks(_chunk, tasks, executor="processes", workers=len(chunks))
    else:
        parts = [_run(module, P, X0, **opts)]
    lyap = None if not tangent else np.concatenate([r.lyapunov for r in parts])
    return MapRun(
        poincare=np.concatenate([r.poincare for r in parts]),
        xmin=np.concatenate([r.xmin for r in parts]),
        xmax=np.concatenate([r.xmax for r in parts]),
        lyapunov=lyap,
        nfev=np.concatenate([r.nfev for r in parts]),
        nsteps=np.concatenate([r.nsteps for r in parts]),
        status=tuple(s for r in parts for s in r.status),
        t_fail=np.concatenate([r.t_fail for r in parts]),
        wall_time=time.perf_counter() - started,
        backend=backend,
    )


def _chunk(task) -> MapRun:
    source, P, X0, opts = task
    return _run(load_generated(source), P, X0, **opts)


def _run(
    module,
    P,
    X0,
    *,
    method,
    rtol,
    atol,
    transient,
    periods,
    lyapunov_periods,
    bound,
    max_steps,
    group,
    seed,
    backend,
) -> MapRun:
    if backend == "numpy":
        n = X0.shape[1]
        w0 = _tangent(n, seed) if lyapunov_periods > 0 else None
        fields = numpy_map(
            module,
            P,
            X0,
            w0,
            method=method,
            rtol=rtol,
            atol=atol,
            transient=transient,
            periods=periods,
            lyapunov_periods=lyapunov_periods,
            bound=bound,
            max_steps=max_steps,
        )
        return MapRun(**fields, backend="numpy")
    contract = Contract.of(module)
    n = len(contract.states)
    tangent = lyapunov_periods > 0
    lib, _ = library(module, variational=tangent)
    started = time.perf_counter()
    N = P.shape[0]
    Z0 = np.hstack([X0, np.tile(_tangent(n, seed), (N, 1))]) if tangent else X0
    Z0 = np.ascontiguousarray(Z0)
    limits = np.full(n, np.inf)
    for c, b in (contract.valid_range or {}).items():
        limits[contract.states.index(c)] = b
    limits = np.ascontiguousarray(limits)
    poinc = np.empty((N, periods + 1, n))
    xmin, xmax = np.empty((N, n)), np.empty((N, n))
    lyap = np.empty((N, max(lyapunov_periods, 1)))
    nfev, nsteps = np.zeros(N, dtype=np.int64), np.zeros(N, dtype=np.int64)
    status, t_fail = np.zeros(N, dtype=np.int32), np.zeros(N)
    period = 2.0 * np.pi / float(P[0, contract.parameters.index(contract.forcing_frequency)])
    code = lib.gs_map_lockstep(
        _CODES[method],
        N,
        int(group),
        np.ascontiguousarray(P),
        Z0,
        0.0,
        period,
        int(transient),
        int(periods),
        int(tangent),
        int(lyapunov_periods),
        limits.ctypes.data,
        float(rtol),
        float(atol),
        float(bound),
        int(max_steps),
        poinc,
        xmin,
        xmax,
        lyap.ctypes.data,
        nfev,
        nsteps,
        status,
        t_fail,
    )
    if code != 0:
        raise MemoryError("the map integrator could not allocate its work arrays")
    return MapRun(
        poincare=poinc,
        xmin=xmin,
        xmax=xmax,
        lyapunov=lyap if tangent else None,
        nfev=nfev,
        nsteps=nsteps,
        status=tuple(MAP_STATUS[int(s)] for s in status),
        t_fail=t_fail,
        wall_time=time.perf_counter() - started,
    )
