"""Runs in the excitation phase ``s = omega tau``: points of different forcing frequency in
one lockstep group.

In ``s`` every point's forcing period is ``2 pi``: ``dX/ds = f(s / omega, X) / omega`` with
each point's own ``omega``, so a group of frequencies shares the time grid and the step
(the compiled engine's ``gs_run_phase``).  The state stays the physical one (coordinates
and their derivatives in ``tau``), so a run at one frequency can start from another's end
state: a frequency sweep with continuation of the state is a chain of such runs.  Without
a compiler the same runs go through SciPy's DOP853 point by point, with a warning.
"""

from __future__ import annotations

import time

import numpy as np

from ...contract import Contract
from .batch import _CODES, STATUS, BatchResult, fallback_warning
from .build import NativeUnavailable, library

__all__ = ["run_phase"]


def run_phase(
    module,
    P,
    X0,
    *,
    method: str = "dop853",
    rtol: float = 1e-8,
    atol: float = 1e-10,
    transient: int = 300,
    periods: int = 100,
    samples_per_period: int = 64,
    bound: float = 1e3,
    max_steps: int = 50_000_000,
    group: int = 64,
) -> BatchResult:
    """Integrate every point ``P[i]`` from ``X0[i]`` over ``transient + periods`` forcing
    periods in the phase; ``t`` of the result is the phase ``s`` of the samples
    (``2 pi (transient + k / samples_per_period)``), the same for every point (divide by
    each point's omega for tau)."""
    if method not in ("dopri5", "dop853"):
        raise ValueError(f"method must be dopri5 or dop853 in the phase, got '{method}'")
    P = np.ascontiguousarray(np.atleast_2d(np.asarray(P, dtype=float)))
    X0 = np.ascontiguousarray(np.atleast_2d(np.asarray(X0, dtype=float)))
    contract = Contract.of(module)
    n = len(contract.states)
    if P.shape[1] != len(contract.parameters) or X0.shape != (P.shape[0], n):
        raise ValueError(f"P must be (N, {len(contract.parameters)}) and X0 (N, {n})")
    if not (np.all(np.isfinite(P)) and np.all(np.isfinite(X0))):
        raise ValueError("P and X0 must hold finite numbers only")
    iw = contract.parameters.index(contract.forcing_frequency)
    if not np.all(P[:, iw] > 0):
        raise ValueError(f"{contract.forcing_frequency} must be positive at every point")
    spp = int(samples_per_period)
    k = periods * spp + 1
    s = 2 * np.pi * (transient + np.arange(k) / spp)
    started = time.perf_counter()
    N = P.shape[0]
    try:
        lib, facts = library(module)
    except NativeUnavailable as err:
        fallback_warning(err, "integrating with SciPy's DOP853 point by point instead")
        return _scipy(module, P, X0, s, iw, rtol, atol, bound, started)
    out = np.empty((N, k, n))
    nfev = np.zeros(N, dtype=np.int64)
    nsteps = np.zeros(N, dtype=np.int64)
    status = np.zeros(N, dtype=np.int32)
    t_fail = np.zeros(N)
    exits = np.full((N, 3), np.nan)
    bounds = np.full(n, np.inf)
    for c, b in (contract.valid_range or {}).items():
        bounds[contract.states.index(c)] = b
    code = lib.gs_run_phase(
        _CODES[method], N, int(group), P, X0, 0.0, iw, int(transient), int(periods), spp, 1,
        float(rtol), float(atol), float(bound), int(max_steps), out, nfev, nsteps, status,
        t_fail, bounds, 0, exits,
    )  # fmt: skip
    exits[:, 0] /= P[:, iw]  # the phase s = omega tau, back to tau
    if code == -1:
        raise MemoryError("the phase integrator could not allocate its work arrays")
    if code != 0:
        raise ValueError(f"the phase integrator refused its input (code {code})")
    return BatchResult(
        t=s,
        x=out,
        nfev=nfev,
        nsteps=nsteps,
        status=tuple(STATUS.get(int(v), "left the valid range") for v in status),
        t_fail=t_fail,
        backend="native",
        wall_time=time.perf_counter() - started,
        compile_seconds=facts["seconds"],
        exits=exits,
    )


def _scipy(module, P, X0, s, iw, rtol, atol, bound, started) -> BatchResult:
    from scipy.integrate import solve_ivp

    N, n = X0.shape
    out = np.full((N, s.size, n), np.nan)
    status, t_fail, nfev = [], np.full(N, np.nan), np.zeros(N, dtype=np.int64)
    for j in range(N):
        p, w = P[j], P[j, iw]

        def f(t, x, p=p, w=w):
            return np.asarray(module.rhs(t / w, x, p), float) / w

        sol = solve_ivp(f, (0.0, s[-1]), X0[j], method="DOP853", t_eval=s, rtol=rtol,
                        atol=atol)  # fmt: skip
        nfev[j] = sol.nfev
        ok = sol.success and sol.y.shape[1] == s.size and np.all(np.abs(sol.y) <= bound)
        status.append("ok" if ok else "divergent")
        if ok:
            out[j] = sol.y.T
        else:
            t_fail[j] = sol.t[-1] if sol.t.size else 0.0
    return BatchResult(s, out, nfev, nfev // 12, tuple(status), t_fail, "numpy",
                       time.perf_counter() - started)  # fmt: skip
