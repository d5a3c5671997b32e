"""Runs without a compiler: the compiled engine's contract on NumPy and SciPy.

:func:`run_fallback` takes the same ``(module, P, X0, spec)`` as the compiled engine and
returns the same :class:`~..spec.RunResult`, every field with the same meaning, point by
point on the generated NumPy code:

* ``dopri5`` and ``dop853``: SciPy's ``RK45`` and ``DOP853`` steppers (the step control
  the C engine follows, ``native_*.c``), stopped on every sample time
  ``t0 + (j / samples_per_period) T``, the step size carried over from one stop to the
  next; ``rk4``: the classic tableau (``tableau.py``) on the fixed grid
  ``t0 + j T / steps_per_period``, as the C engine steps it;
* time mode ``"phase"``: ``dX/ds = f(s / omega, X) / omega`` with each point's own
  ``omega`` (period ``2 pi``), the state kept physical;
* after every accepted step: finiteness, the escape ``bound`` and the force law's valid
  range (the contract's ``valid_range``: the first exit located on the step's cubic
  Hermite interpolant, as the C engine does, then recorded or the point stopped), and over
  the sampled window the extremes of every state;
* with ``"exponent"`` collected, the tangent vector of the variational equations
  (``integrate/variational.py``: ``w' = J w`` with the generated ``jacobian``) beside the
  state from the start, renormalised every forcing period and ``log |w|`` summed over the
  last ``lyapunov_periods`` periods (Benettin, Galgani, Giorgilli and Strelcyn 1980,
  Meccanica 15), from the unit vector the C engine starts from (:func:`tangent_start`).

``nfev`` and ``nsteps`` are this stepping's own counts (right-hand-side calls, accepted
steps). The solution agrees with the compiled engine's to the integration tolerance (the
step sequences differ a little: SciPy's error norm also counts the trace of ``J`` that
``numpy_rhs`` carries). Cost: one Python step per point and step, some 300 times the
compiled engine's time.
"""

from __future__ import annotations

import time
import warnings
from dataclasses import dataclass, replace

import numpy as np

from ..._warnings import NativeFallback
from ...contract import Contract
from ..spec import RunResult, RunSpec
from ..tableau import RK4, rk_step
from ..variational import numpy_rhs

__all__ = ["fallback_warning", "run_fallback", "tangent_start"]

_STEPPERS = {"dopri5": "RK45", "dop853": "DOP853"}
_warned: set[str] = set()


def fallback_warning(err: Exception, instead: str = "integrating with NumPy instead") -> None:
    """The one warning line of a run that goes without the compiled library: why, and what
    runs instead; once per reason and session (``native.reset`` forgets)."""
    text = f"{err}; {instead} (slower)"
    if text not in _warned:
        _warned.add(text)
        warnings.warn(text, NativeFallback, stacklevel=3)


def tangent_start(n: int, seed: int) -> np.ndarray:
    """The tangent vector's start, shape (n,): a unit normal draw from ``seed``."""
    v = np.random.default_rng(seed).standard_normal(n)
    return v / np.linalg.norm(v)


@dataclass(frozen=True)
class _Setup:
    """What every point of one run shares."""

    spec: RunSpec
    n: int
    limits: np.ndarray  # (n,) bounds |x_i| <= limits[i] (inf: none)
    period: float  # forcing period in the time mode (2 pi in the phase)
    w0: np.ndarray | None  # tangent start, or None without the exponent


def run_fallback(module, P: np.ndarray, X0: np.ndarray, spec: RunSpec, tangent0=None) -> RunResult:
    """Integrate ``P`` (N, P) from ``X0`` (N, n) as ``spec`` says, without compiled code.
    ``tangent0`` (N, n): each point's tangent start, as the compiled engine takes it.

    The inputs as ``integrate()`` checked them (finite, ``omega > 0``, one ``omega`` in
    the time mode ``"tau"``). Returns a :class:`RunResult` with backend ``"numpy"``.
    """
    contract = Contract.of(module)
    n = len(contract.states)
    iw = contract.parameters.index(contract.forcing_frequency)
    limits = np.full(n, np.inf)
    if spec.valid_range != "ignore":
        for i, b in contract.valid_bounds():
            limits[i] = b
    period = 2.0 * np.pi if spec.time == "phase" else 2.0 * np.pi / float(P[0, iw])
    tangent = "exponent" in spec.collect
    setup = _Setup(spec, n, limits, period, tangent_start(n, spec.seed) if tangent else None)
    started = time.perf_counter()
    N = P.shape[0]
    out = {
        "x": np.full((N, spec.n_samples, n), np.nan),
        "xmin": np.full((N, n), np.nan),
        "xmax": np.full((N, n), np.nan),
        "exponent": np.full((N, max(spec.lyapunov_periods, 1)), np.nan),
        "nfev": np.zeros(N, dtype=np.int64),
        "nsteps": np.zeros(N, dtype=np.int64),
        "t_fail": np.full(N, np.nan),
        "exits": np.full((N, 3), np.nan),
        "tangent": np.full((N, n + 1), np.nan),
    }
    status = tuple(
        _one(
            module,
            setup if tangent0 is None else replace(setup, w0=np.asarray(tangent0[i], float)),
            P[i],
            X0[i],
            float(P[i, iw]),
            i,
            out,
        )
        for i in range(N)
    )
    if spec.time == "phase":
        out["exits"][:, 0] /= P[:, iw]  # the phase s = omega tau, back to tau
    keep = spec.collect
    return RunResult(
        t=spec.sample_times(period),
        x=out["x"] if "samples" in keep else None,
        nfev=out["nfev"],
        nsteps=out["nsteps"],
        status=status,
        t_fail=out["t_fail"],
        method=spec.method,
        backend="numpy",
        xmin=out["xmin"] if "extremes" in keep else None,
        xmax=out["xmax"] if "extremes" in keep else None,
        exponent=out["exponent"] if tangent else None,
        exits=None if spec.valid_range == "ignore" else out["exits"],
        tangent=None if tangent0 is None else out["tangent"],
        wall_time=time.perf_counter() - started,
    )


def _rhs(module, p, n: int, omega: float, tangent: bool, phase: bool):
    """The right-hand side of the stepped state: ``x``, or ``(x, w, int trace J)``."""
    if tangent:
        f = numpy_rhs(module, p, n, tangents=1)
    else:

        def f(t, x):
            return module.rhs(t, x, p)

    if not phase:
        return f

    def g(s, z):
        return np.asarray(f(s / omega, z), dtype=float) / omega

    return g


def _check(z, n: int, bound: float, limits: np.ndarray, stop: bool) -> str:
    """The C engine's check after a step: every component finite, the physical state
    within ``bound`` and, with ``stop``, within the valid range."""
    if not np.all(np.isfinite(z)):
        return "not finite"
    x = np.abs(z[:n])
    if np.any(x > bound):
        return "divergent"
    if stop and np.any(x > limits):
        return "left the valid range"
    return "ok"


def _hermite(y0, y1, f0, f1, h, s):
    """The cubic Hermite interpolant of a step of length ``h`` at fraction ``s``."""
    a = 2 * s**3 - 3 * s**2 + 1
    b = s**3 - 2 * s**2 + s
    c = -2 * s**3 + 3 * s**2
    d = s**3 - s**2
    return a * y0 + h * b * f0 + c * y1 + h * d * f1


def _crossing(step, limits: np.ndarray, n: int):
    """``(fraction, index, value)`` of the first exit from the valid range on the step
    ``(t, h, y0, y1, f0, f1)``, or None (bisection on the Hermite interpolant)."""
    t, h, y0, y1, f0, f1 = step
    best = None
    for i in np.flatnonzero(np.abs(y1[:n]) > limits):
        lo, hi = 0.0, 1.0
        if abs(y0[i]) > limits[i]:
            hi = 0.0
        for _ in range(60):
            if hi - lo <= 1e-15:
                break
            mid = 0.5 * (lo + hi)
            if abs(_hermite(y0[i], y1[i], f0[i], f1[i], h, mid)) > limits[i]:
                hi = mid
            else:
                lo = mid
        if best is None or hi < best[0]:
            best = (hi, int(i), float(_hermite(y0[i], y1[i], f0[i], f1[i], h, hi)))
    return best


class _Point:
    """One point's stepping state: ``t``, ``z``, the step carried over, the counts."""

    def __init__(self, rhs, t0: float, z0: np.ndarray):
        self.bad: list = []  # a non-finite right-hand side: SciPy then fails the step
        self.f = rhs
        self.t, self.z, self.h = t0, np.array(z0, dtype=float), None
        self.nfev, self.nsteps = 0, 0

    def rhs(self, t, y):
        self.nfev += 1
        dy = np.asarray(self.f(t, y), dtype=float)
        if not np.all(np.isfinite(dy)):
            self.bad.append(t)
        return dy


def _one(module, setup: _Setup, p, x0, omega: float, i: int, out: dict) -> str:
    """Run point ``i``, fill its rows of ``out`` and return its status."""
    spec, n, limits = setup.spec, setup.n, setup.limits
    tangent = setup.w0 is not None
    rhs = _rhs(module, p, n, omega, tangent, spec.time == "phase")
    z0 = np.concatenate([x0, setup.w0, [0.0]]) if tangent else x0
    pt = _Point(rhs, spec.t0, z0)
    spp = spec.samples_per_period
    dt = setup.period / spp
    first = spec.transient * spp
    stops = (spec.transient + spec.periods) * spp
    lyap_from = spec.transient + spec.periods - spec.lyapunov_periods  # in periods
    tau_period = 2.0 * np.pi / omega
    stop = spec.valid_range == "stop"
    growth = 0.0
    state = _check(pt.z, n, spec.bound, limits, stop)
    if state == "ok" and not np.all(np.isfinite(pt.rhs(spec.t0, pt.z))):
        state = "not finite"
    if state != "ok":
        out["t_fail"][i] = spec.t0
    for j in range(stops + 1):
        if j > 0:
            state = _advance(pt, spec.t0 + j * dt, j > first, setup, i, out)
        if state != "ok":
            break
        if j >= first:
            out["x"][i, j - first] = pt.z[:n]
            if j == first:
                out["xmin"][i], out["xmax"][i] = pt.z[:n], pt.z[:n]
        if tangent and j % spp == 0:
            g = float(np.linalg.norm(pt.z[n : 2 * n]))
            if not (np.isfinite(g) and g > 0.0):
                state, out["t_fail"][i] = "not finite", pt.t
                break
            pt.z[n : 2 * n] /= g
            k = j // spp
            if k > lyap_from:
                growth += np.log(g)
                out["exponent"][i, k - lyap_from - 1] = growth / ((k - lyap_from) * tau_period)
    if state != "ok":
        out["exponent"][i] = np.nan
    elif tangent:  # the tangent's end (unit length after the last stop), its log growth
        out["tangent"][i] = np.r_[pt.z[n : 2 * n], growth]
    out["nfev"][i], out["nsteps"][i] = pt.nfev, pt.nsteps
    return state


def _advance(pt: _Point, target: float, window: bool, setup: _Setup, i: int, out: dict) -> str:
    """Step point ``i`` from ``pt.t`` to ``target``, checking after every accepted step;
    ``window``: the steps lie in the sampled window (extremes kept)."""
    spec = setup.spec
    for step in _steps(pt, target, spec, setup.period):
        if isinstance(step, str):
            state = step
        else:
            pt.nsteps += 1
            state = _after_step(pt, step, window, setup, i, out)
            if state == "ok" and pt.nsteps >= spec.max_steps and pt.t < target:
                state = "too many steps"
        if state != "ok":
            if state != "left the valid range":
                out["t_fail"][i] = pt.t
            return state
    pt.z = pt.z.copy()  # the stepper's array: renormalised in place after a period
    return "ok"


def _after_step(pt: _Point, step, window: bool, setup: _Setup, i: int, out: dict) -> str:
    spec, n, limits = setup.spec, setup.n, setup.limits
    state = _check(pt.z, n, spec.bound, limits, False)
    if state != "ok":
        return state
    if spec.valid_range != "ignore" and np.isnan(out["exits"][i, 0]):
        if step[4] is None and np.any(np.abs(step[3][:n]) > limits):
            t, h, y0, y1 = step[:4]
            step = (t, h, y0, y1, pt.rhs(t, y0), pt.rhs(t + h, y1))
        hit = _crossing(step, limits, n)
        if hit is not None:
            s, k, value = hit
            out["exits"][i] = (step[0] + s * step[1], k, value)
            if spec.valid_range == "stop":
                out["t_fail"][i] = out["exits"][i, 0]
                return "left the valid range"
    if window:
        x = pt.z[:n]
        np.minimum(out["xmin"][i], x, out=out["xmin"][i])
        np.maximum(out["xmax"][i], x, out=out["xmax"][i])
    return "ok"


def _steps(pt: _Point, target: float, spec: RunSpec, period: float):
    """Accepted steps to ``target``: each ``(t, h, y0, y1, f0, f1)`` after ``pt`` moved
    (the slopes None where the stepper does not keep them), or a failure status."""
    if not spec.adaptive:
        h = period / spec.steps_per_period
        j0 = round((pt.t - spec.t0) / h)
        j1 = round((target - spec.t0) / h)
        for j in range(j0, j1):
            t, y0 = spec.t0 + j * h, pt.z
            pt.z = rk_step(RK4, pt.rhs, t, y0, h)
            pt.t = spec.t0 + (j + 1) * h
            yield (t, h, y0, pt.z, None, None)  # slopes: only where a crossing is located
        return
    import scipy.integrate

    stepper = getattr(scipy.integrate, _STEPPERS[spec.method])
    first = None if pt.h is None else min(pt.h, target - pt.t)
    run = stepper(pt.rhs, pt.t, pt.z, target, rtol=spec.rtol, atol=spec.atol, first_step=first)
    proposal = run.h_abs
    while run.status == "running":
        proposal = run.h_abs  # kept: the last step is clipped to land on the stop
        t, y0, f0 = run.t, run.y.copy(), run.f.copy()
        pt.bad.clear()
        run.step()
        if run.status == "failed":
            pt.t = run.t
            yield "not finite" if pt.bad else "step too small"
            return
        pt.t, pt.z = run.t, run.y
        yield (t, run.t - t, y0, run.y, f0, run.f)
    pt.h = max(proposal, run.h_abs)
