"""Batched integration of many parameter points in native code, with a NumPy fallback.

``run_batch(module, P, X0, ...)`` integrates many parameter points of one generated model
in one call of native code: Dormand-Prince 5(4) (``dopri5``), DOP853 (``dop853``) or
classic RK4 (``rk4``), with the step control of SciPy's RK45/DOP853, sampled ``spp`` times
per forcing period after a transient (``_native.c``).  Points either share time and step
size in lockstep groups (the excitation computed once per stage for the group) or take
their own steps.  Without a working compiler everything still runs through NumPy/SciPy
(SciPy's RK45/DOP853 point by point, or the RK4 tableau on all points at once), with a
warning.
"""

from __future__ import annotations

import time
import warnings
from dataclasses import dataclass

import numpy as np

from ...contract import Contract, load_generated
from ..events import escape_event
from ..tableau import RK4, rk_step
from .build import NativeFallback, NativeUnavailable, library

__all__ = ["NATIVE_METHODS", "STATUS", "BatchResult", "benettin", "fallback_warning", "run_batch"]

NATIVE_METHODS = ("dopri5", "dop853", "rk4")
_CODES = {"dopri5": 0, "dop853": 1, "rk4": 2}
STATUS = {0: "ok", 1: "divergent", 2: "too many steps", 3: "not finite", 4: "step too small",
          5: "left the valid range"}  # fmt: skip
_warned: set[str] = set()


def fallback_warning(err: Exception, instead: str = "integrating with NumPy instead") -> None:
    """The one warning line of a run that goes without the compiled library: why, and what
    runs instead; once per reason and session (``native.reset`` forgets)."""
    text = f"{err}; {instead} (slower)"
    if text not in _warned:
        _warned.add(text)
        warnings.warn(text, NativeFallback, stacklevel=3)


@dataclass(frozen=True)
class BatchResult:
    """Samples of many points: ``x`` (N, K, n) at ``t`` (K,), with per-point work and status."""

    t: np.ndarray
    x: np.ndarray
    nfev: np.ndarray
    nsteps: np.ndarray
    status: tuple[str, ...]
    t_fail: np.ndarray
    backend: str  # "native" or "numpy"
    wall_time: float
    compile_seconds: float = 0.0
    # (N, 3): tau, state index, value of each point's first exit from the valid range
    # (tau NaN: none), located on the accepted steps; None where not tracked (NumPy)
    exits: np.ndarray | None = None


def run_batch(
    module,
    P,
    X0,
    *,
    method: str = "dop853",
    rtol: float = 1e-8,
    atol: float = 1e-10,
    t0: float = 0.0,
    transient: int = 300,
    periods: int = 100,
    samples_per_period: int = 1,
    steps_per_period: int = 256,
    bound: float = 1e3,
    max_steps: int = 50_000_000,
    lockstep: bool = True,
    group: int = 64,
    workers: int = 1,
    fallback: bool = True,
    dense: bool = True,
    valid_range=None,
    stop_on_exit: bool = False,
) -> BatchResult:
    """Integrate every column set ``P[i]`` (parameters) from ``X0[i]`` of ``module``.

    ``P``: (N, P) parameter vectors (``module.parameters(...)``); ``X0``: (N, n).  The
    excitation period is ``2 pi / omega`` with ``omega`` the contract's forcing frequency
    (the same for all points).
    Samples: ``t0 + (transient + k / samples_per_period) T`` for
    ``k = 0 .. periods * samples_per_period`` (the last one closes the window).

    ``lockstep``: groups of ``group`` points share time and step size (the excitation is
    computed once per stage for the group and the arithmetic vectorises); otherwise each
    point takes its own steps.  RK4 always runs point by point.

    ``dense``: lockstep DOP853 takes its natural steps and interpolates the samples with
    its seventh-order dense output (three more stages in a step that holds a sample)
    instead of shortening steps to land on them; False shortens the steps (as RK45 and
    the per-point engine always do).

    ``valid_range``: a bound per state (``inf``: none), checked at every accepted step
    with the crossing located on the step's Hermite interpolant (``exits``);
    ``stop_on_exit`` stops a point there (status "left the valid range").
    """
    if method not in NATIVE_METHODS:
        raise ValueError(f"unknown native method '{method}'; methods: {', '.join(NATIVE_METHODS)}")
    P = np.ascontiguousarray(np.atleast_2d(np.asarray(P, dtype=float)))
    X0 = np.ascontiguousarray(np.atleast_2d(np.asarray(X0, dtype=float)))
    contract = Contract.of(module)
    n, n_p = len(contract.states), len(contract.parameters)
    if P.shape[1] != n_p or X0.shape != (P.shape[0], n):
        raise ValueError(f"P must be (N, {n_p}) and X0 (N, {n}); got {P.shape} and {X0.shape}")
    if not (np.all(np.isfinite(P)) and np.all(np.isfinite(X0))):
        bad = "P" if not np.all(np.isfinite(P)) else "X0"
        raise ValueError(
            f"{bad} holds a NaN or infinite value; every parameter and initial "
            "state must be a finite number"
        )
    w_name = contract.forcing_frequency
    omega = P[:, contract.parameters.index(w_name)]
    if not (np.all(np.isfinite(omega)) and np.all(omega > 0)) or np.ptp(omega) != 0.0:
        raise ValueError(f"{w_name} must be positive and the same for every point")
    if not (rtol > 0 and atol > 0):
        raise ValueError(f"tolerances must be > 0, got rtol={rtol}, atol={atol}")
    spp = int(samples_per_period)
    if method == "rk4" and (steps_per_period < spp or steps_per_period % spp):
        raise ValueError(
            f"steps_per_period ({steps_per_period}) must be a multiple of samples_per_period "
            f"({spp}) for rk4"
        )
    period = 2.0 * np.pi / float(omega[0])
    k = periods * spp + 1
    t = t0 + (transient + np.arange(k) / spp) * period
    started = time.perf_counter()
    if contract.piecewise:
        # A piecewise force law (the dead zone): each point's kinks would shrink the step
        # of the whole group, so such models run point by point.
        lockstep = False
    opts = dict(
        method=method,
        rtol=rtol,
        atol=atol,
        t0=t0,
        transient=transient,
        periods=periods,
        samples_per_period=spp,
        steps_per_period=steps_per_period,
        bound=bound,
        max_steps=max_steps,
        lockstep=lockstep,
        group=group,
        fallback=fallback,
        dense=dense,
        valid_range=valid_range,
        stop_on_exit=stop_on_exit,
    )
    bounds = np.full(n, np.inf) if valid_range is None else np.asarray(valid_range, float)
    if bounds.shape != (n,):
        raise ValueError(f"valid_range must hold {n} bounds, one per state")
    bounds = np.ascontiguousarray(bounds)
    if workers > 1 and P.shape[0] > 1:
        return _parallel(module, P, X0, workers, started, opts)
    try:
        lib, facts = library(module)
    except NativeUnavailable as err:
        if not fallback:
            raise
        fallback_warning(err)
        return _numpy_batch(module, P, X0, t, period, started, opts)
    N = P.shape[0]
    out = np.empty((N, k, n))
    nfev = np.zeros(N, dtype=np.int64)
    nsteps = np.zeros(N, dtype=np.int64)
    status = np.zeros(N, dtype=np.int32)
    t_fail = np.zeros(N)
    exits = np.full((N, 3), np.nan)
    if lockstep and method != "rk4" and N > 1:
        code = lib.gs_run_lockstep(
            _CODES[method],
            N,
            int(group),
            P,
            X0,
            float(t0),
            period,
            int(transient),
            int(periods),
            spp,
            int(dense),
            float(rtol),
            float(atol),
            float(bound),
            int(max_steps),
            out,
            nfev,
            nsteps,
            status,
            t_fail,
            bounds,
            int(stop_on_exit),
            exits,
        )
        if code != 0:
            raise MemoryError("the lockstep integrator could not allocate its work arrays")
    else:
        lib.gs_run(
            _CODES[method],
            N,
            P,
            X0,
            float(t0),
            period,
            int(transient),
            int(periods),
            spp,
            float(rtol),
            float(atol),
            int(steps_per_period),
            float(bound),
            int(max_steps),
            out,
            nfev,
            nsteps,
            status,
            t_fail,
            bounds,
            int(stop_on_exit),
            exits,
        )
    return BatchResult(
        t=t,
        x=out,
        nfev=nfev,
        nsteps=nsteps,
        status=tuple(STATUS[int(s)] for s in status),
        t_fail=t_fail,
        backend="native",
        wall_time=time.perf_counter() - started,
        compile_seconds=facts["seconds"],
        exits=exits,
    )


def _chunk(task):
    source, P, X0, kwargs = task
    return run_batch(load_generated(source), P, X0, **kwargs)


def _parallel(module, P, X0, workers, started, kwargs) -> BatchResult:
    """Split the points into ``workers`` contiguous chunks run by as many processes."""
    from ...sweep.executor import map_tasks

    try:
        library(module)  # compile once here, not in every worker
    except NativeUnavailable:
        if not kwargs.get("fallback", True):
            raise
        return run_batch(module, P, X0, **kwargs)  # the NumPy path, in this process
    chunks = [c for c in np.array_split(np.arange(P.shape[0]), workers) if c.size]
    tasks = [(module.__file__, P[c], X0[c], kwargs) for c in chunks]
    parts = map_tasks(_chunk, tasks, executor="processes", workers=len(chunks))
    return BatchResult(
        t=parts[0].t,
        x=np.concatenate([r.x for r in parts]),
        nfev=np.concatenate([r.nfev for r in parts]),
        nsteps=np.concatenate([r.nsteps for r in parts]),
        status=tuple(s for r in parts for s in r.status),
        t_fail=np.concatenate([r.t_fail for r in parts]),
        backend=parts[0].backend,
        wall_time=time.perf_counter() - started,
        exits=None if parts[0].exits is None else np.concatenate([r.exits for r in parts]),
    )


def _numpy_batch(module, P, X0, t, period, started, opts: dict) -> BatchResult:
    """The same integration without a compiler: SciPy's RK45/DOP853 point by point on the
    generated NumPy right-hand side (each with an escape event at ``bound``), or NumPy RK4
    on all points at once, on the same grid as the C code (``opts``: run_batch's)."""
    from scipy.integrate import solve_ivp

    method, rtol, atol, t0 = opts["method"], opts["rtol"], opts["atol"], opts["t0"]
    transient, periods, bound = opts["transient"], opts["periods"], opts["bound"]
    spp, steps_per_period = opts["samples_per_period"], opts["steps_per_period"]

    N, n = X0.shape
    Pt = P.T.copy()
    if method == "rk4":
        h = period / steps_per_period
        y = X0.T.copy()
        out = np.empty((N, len(t), n))
        steps_total = (transient + periods) * steps_per_period
        stride = steps_per_period // spp
        first = transient * steps_per_period
        for j in range(steps_total + 1):
            if j >= first and (j - first) % stride == 0:
                out[:, (j - first) // stride, :] = y.T
            if j == steps_total:
                break
            y = rk_step(RK4, lambda tt, yy: module.rhs(tt, yy, Pt), t0 + j * h, y, h)
        nfev = np.full(N, 4 * steps_total)
        nsteps = np.full(N, steps_total)
        finite = np.all(np.isfinite(out), axis=(1, 2))
        big = np.any(np.abs(np.nan_to_num(out)) > bound, axis=(1, 2))
        status = tuple(
            "ok" if f and not b else ("divergent" if b else "not finite")
            for f, b in zip(finite, big, strict=True)
        )
        t_fail = np.full(N, np.nan)
    else:
        # point by point, each stopped by its own escape event (a diverging point must not
        # hold up the others, as one stacked system would)
        out = np.full((N, len(t), n), np.nan)
        nfev = np.zeros(N, dtype=np.int64)
        nsteps = np.zeros(N, dtype=np.int64)
        status, t_fail = [], np.full(N, np.nan)

        escape = escape_event(bound)
        for i in range(N):
            sol = solve_ivp(
                lambda tt, yy, pp=P[i]: module.rhs(tt, yy, pp),
                (t0, t[-1]),
                X0[i],
                method="RK45" if method == "dopri5" else "DOP853",
                t_eval=t,
                rtol=rtol,
                atol=atol,
                events=escape,
            )
            ys = np.asarray(sol.y, dtype=float).reshape(n, -1)  # [] when no sample was reached
            out[i, : ys.shape[1], :] = ys.T
            nfev[i], nsteps[i] = sol.nfev, len(sol.t)
            if sol.status == 1:
                status.append("divergent")
                t_fail[i] = float(sol.t_events[0][0])
            elif sol.status != 0 or not np.all(np.isfinite(ys)):
                status.append("not finite")
                t_fail[i] = float(sol.t[-1]) if sol.t.size else t0
            else:
                status.append("ok")
        status = tuple(status)
    return BatchResult(
        t=t,
        x=out,
        nfev=nfev,
        nsteps=nsteps,
        status=status,
        t_fail=t_fail,
        backend="numpy",
        wall_time=time.perf_counter() - started,
    )


def benettin(module, p, z0, *, t0: float, period: float, periods: int, rtol: float, atol: float):
    """Running estimate of the largest Lyapunov exponent (``analysis/lyapunov.py``) in native
    code: DOP853 on the variational equations, renormalised every period.  Returns
    ``(running, nfev)``; raises :class:`NativeUnavailable` without a compiler and
    ``FloatingPointError`` when the run fails."""
    lib, _ = library(module, variational=True)
    p = np.ascontiguousarray(p, dtype=float)
    z0 = np.ascontiguousarray(z0, dtype=float)
    running = np.empty(periods)
    nfev = np.zeros(1, dtype=np.int64)
    status = lib.gs_benettin(
        p,
        z0,
        float(t0),
        period,
        int(periods),
        float(rtol),
        float(atol),
        1e12,
        50_000_000,
        running,
        nfev,
    )
    if status != 0:
        raise FloatingPointError(f"variational integration stopped: {STATUS[status]}")
    return running, int(nfev[0])
