"""Map runs without a compiler: the compiled map engine's contract on SciPy's integrators.

:func:`numpy_map` returns the fields of ``run_map``'s :class:`~.maps.MapRun` from the same
inputs, each with the same meaning, point by point on the generated NumPy code:

* SciPy's ``RK45`` (``dopri5``) or ``DOP853`` stepper (the step control the C engine
  follows, ``_native.c``), stopped on every forcing period ``t0 + k T`` as the C engine's
  steps are, the step size carried over from one period to the next;
* after every accepted step: finiteness, the escape ``bound`` and the force law's valid
  range (the contract's ``valid_range``) on the physical state, and over the window of the
  last ``periods`` periods the extremes of every state;
* with ``lyapunov_periods > 0`` the tangent vector of the variational equations
  (``integrate/variational.py``: ``w' = J w`` with the generated ``jacobian``) beside the
  state from the start, renormalised every period and ``log |w|`` summed over the last
  ``lyapunov_periods`` periods (Benettin, Galgani, Giorgilli and Strelcyn 1980,
  Meccanica 15), from the unit vector ``w0`` that the C engine starts from.

The solution agrees with the compiled engine's to the integration tolerance (the step
sequences differ a little: SciPy's error norm also counts the trace of ``J`` that
``numpy_rhs`` carries).  Cost: one Python step per point and step, some 300 times the
compiled engine's time.
"""

from __future__ import annotations

import time

import numpy as np

from ...contract import Contract
from ..variational import numpy_rhs

__all__ = ["numpy_map"]

_STEPPERS = {"dopri5": "RK45", "dop853": "DOP853"}


def numpy_map(
    module,
    P,
    X0,
    w0,
    *,
    method,
    rtol,
    atol,
    transient,
    periods,
    lyapunov_periods,
    bound,
    max_steps,
) -> dict:
    """``run_map``'s runs of ``P`` (N, P) from ``X0`` (N, n) with SciPy, one point at a
    time (the inputs as ``run_map`` checked them; ``w0`` the tangent vector, or None
    without the exponent): the keyword arguments of a ``MapRun`` but its backend."""
    import scipy.integrate

    stepper = getattr(scipy.integrate, _STEPPERS[method])
    contract = Contract.of(module)
    n = len(contract.states)
    limits = np.full(n, np.inf)
    for c, b in (contract.valid_range or {}).items():
        limits[contract.states.index(c)] = b
    period = 2.0 * np.pi / float(P[0, contract.parameters.index(contract.forcing_frequency)])
    started = time.perf_counter()
    N = P.shape[0]
    L = max(lyapunov_periods, 1)
    out = dict(
        poincare=np.full((N, periods + 1, n), np.nan),
        xmin=np.full((N, n), np.inf),
        xmax=np.full((N, n), -np.inf),
        lyapunov=np.full((N, L), np.nan),
        nfev=np.zeros(N, dtype=np.int64),
        nsteps=np.zeros(N, dtype=np.int64),
        t_fail=np.full(N, np.nan),
    )
    status = []
    run = dict(
        period=period,
        transient=transient,
        periods=periods,
        limits=limits,
        lyapunov_periods=lyapunov_periods,
        rtol=rtol,
        atol=atol,
        bound=bound,
        max_steps=max_steps,
    )
    for i in range(N):
        status.append(_one(module, stepper, P[i], X0[i], w0, i, out, **run))
    return dict(
        poincare=out["poincare"],
        xmin=out["xmin"],
        xmax=out["xmax"],
        lyapunov=out["lyapunov"] if w0 is not None else None,
        nfev=out["nfev"],
        nsteps=out["nsteps"],
        status=tuple(status),
        t_fail=out["t_fail"],
        wall_time=time.perf_counter() - started,
    )


def _check(z, n: int, bound: float, limits: np.ndarray) -> str:
    """The C engine's check after a step: every component finite, the physical state
    within ``bound`` and within the valid range."""
    if not np.all(np.isfinite(z)):
        return "not finite"
    x = np.abs(z[:n])
    if np.any(x > bound):
        return "divergent"
    if np.any(x > limits):
        return "left the valid range"
    return "ok"


def _one(
    module,
    stepper,
    p,
    x0,
    w0,
    i,
    out,
    *,
    period,
    transient,
    periods,
    lyapunov_periods,
    limits,
    rtol,
    atol,
    bound,
    max_steps,
) -> str:
    """Run point ``i``, fill its rows of ``out`` and return its status."""
    n = x0.size
    tangent = w0 is not None
    if tangent:
        f = numpy_rhs(module, p, n, tangents=1)  # (x, w, int trace J)
        z = np.concatenate([x0, w0, [0.0]])
    else:

        def f(t, x):
            return module.rhs(t, x, p)

        z = np.array(x0, dtype=float)
    bad = []  # a non-finite right-hand side: SciPy rejects the step until it is too small

    def rhs(t, y):
        dy = np.asarray(f(t, y), dtype=float)
        if not np.all(np.isfinite(dy)):
            bad.append(t)
        return dy

    n_stops = transient + periods + 1
    lyap_from = n_stops - 1 - lyapunov_periods
    t, h, growth, steps, nfev = 0.0, None, 0.0, 0, 1
    state = _check(z, n, bound, limits)
    if state == "ok" and not np.all(np.isfinite(rhs(0.0, z))):
        state = "not finite"
    if state != "ok":
        out["t_fail"][i] = 0.0
    for k in range(n_stops):
        target = k * period
        if k > 0 and state == "ok":
            first = None if h is None else min(h, target - t)
            run = stepper(rhs, t, z, target, rtol=rtol, atol=atol, first_step=first)
            proposal = run.h_abs
            while run.status == "running":
                proposal = run.h_abs  # kept: the last step is clipped to land on the stop
                bad.clear()
                run.step()
                steps += 1
                if run.status == "failed":
                    state = "not finite" if bad else "step too small"
                elif steps >= max_steps:
                    state = "too many steps"
                else:
                    state = _check(run.y, n, bound, limits)
                    if state == "ok" and k > transient:
                        x = run.y[:n]
                        np.minimum(out["xmin"][i], x, out=out["xmin"][i])
                        np.maximum(out["xmax"][i], x, out=out["xmax"][i])
                if state != "ok":
                    out["t_fail"][i] = run.t
                    break
            t, z, h = run.t, run.y.copy(), max(proposal, run.h_abs)
            nfev += run.nfev
        if state != "ok":
            break
        if k >= transient:
            out["poincare"][i, k - transient] = z[:n]
            if k == transient:
                out["xmin"][i], out["xmax"][i] = z[:n], z[:n]
        if tangent:
            g = float(np.linalg.norm(z[n : 2 * n]))
            if not (np.isfinite(g) and g > 0.0):
                state, out["t_fail"][i] = "not finite", t
                break
            z[n : 2 * n] /= g
            if k > lyap_from:
                growth += np.log(g)
                out["lyapunov"][i, k - lyap_from - 1] = growth / ((k - lyap_from) * period)
    if state != "ok":
        out["lyapunov"][i] = np.nan
    out["nfev"][i], out["nsteps"][i] = nfev, steps
    return state
