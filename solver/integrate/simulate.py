"""One front door for time integration: ``simulate(system, ..., method=...)``.

Methods are records of a validated registry (``methods.py``); each family has one back
end that takes a :class:`~.result.Request` and returns a :class:`~.result.Run`:

* SciPy ``solve_ivp`` (``scipy_backend.py``): ``RK45`` (the reference study's
  variable-step Runge-Kutta 4(5)), ``scipy-dop853``, ``LSODA``, ``Radau``, on the generated NumPy
  right-hand side (and its Jacobian for the implicit ones), stopping at every switching
  surface of a piecewise model (``events.py``) so that the method's order holds across
  the kinks;
* CasADi ``integrator`` (``casadi_backend.py``): ``cvodes``, ``rk`` (fixed-step RK4 with
  ``steps_per_period`` steps), ``collocation``, on the CasADi graph of the same equations;
* compiled (``native/``): ``dop853``, ``dopri5`` and ``rk4`` on the generated C
  right-hand side, the fastest; without a C compiler they fall back to NumPy with a
  warning.

Without ``method`` the fastest one that meets the tolerance is used (:func:`fastest_method`).
The run is split into a transient of ``transient`` forcing periods, discarded, and a
sampled window of ``periods`` periods with ``samples_per_period`` samples each, aligned
with the forcing so that every ``samples_per_period``-th sample is a stroboscopic
(Poincare) point.  Every result records the method, the tolerances, the work done, and
how the run ended.
"""

from __future__ import annotations

import math
import time
from dataclasses import replace

import numpy as np

from ..system import System
from .events import SimulationError
from .limits import check_samples, check_start, default_initial_state, samples_for
from .methods import METHODS, get_method
from .result import Request, first_exit
from .trajectory import Trajectory
from .two_tolerances import check_transient_rtol, said, two_runs, two_runs_many

__all__ = [
    "METHODS",
    "SimulationError",
    "Trajectory",
    "check_samples",
    "check_start",
    "default_initial_state",
    "fastest_method",
    "samples_for",
    "simulate",
    "simulate_many",
]


def fastest_method(rtol: float) -> str:
    """The fastest back end that meets ``rtol``, from the measured speed/accuracy trade
    (``docs/performance.md``): compiled ``dop853`` (faster and more accurate than compiled
    ``dopri5`` at every tolerance measured, 1e-3 to 1e-12, and on the exact dead zone as
    accurate as SciPy's located RK45 at equal rtol); ``cvodes``, the fastest uncompiled
    one, without a C compiler or below the tolerances that SciPy-style step control
    honours (100 machine epsilons)."""
    from .native import compiler

    if compiler() is None or rtol < 100 * np.finfo(float).eps:
        return "cvodes"
    return "dop853"


def _check(system: System, req: Request) -> None:
    """The request's options, each with one line naming what is wrong."""
    method, rtol, atol = req.method, req.rtol, req.atol
    transient, periods, on_invalid = req.transient, req.periods, req.on_invalid
    samples_per_period, steps_per_period = req.samples_per_period, req.steps_per_period
    record = get_method(method)
    if on_invalid not in ("warn", "error"):
        raise ValueError(f"on_invalid must be 'warn' or 'error', got {on_invalid!r}")
    for name, value in (("transient", transient), ("periods", periods)):
        if not (isinstance(value, int) and value >= 0):
            raise ValueError(f"{name} must be a whole number >= 0, got {value!r}")
    if periods < 1 or samples_per_period < 1:
        raise ValueError("periods and samples_per_period must be >= 1")
    if not (isinstance(samples_per_period, int) and isinstance(steps_per_period, int)):
        raise ValueError("samples_per_period and steps_per_period must be whole numbers")
    unit = record.step_unit
    if unit and (
        steps_per_period < unit * samples_per_period
        or steps_per_period % (unit * samples_per_period)
    ):
        raise ValueError(
            f"steps_per_period ({steps_per_period}) must be a multiple of "
            f"{f'{unit} x ' if unit > 1 else ''}samples_per_period ({samples_per_period}) "
            f"for '{method}', so that every sample interval holds whole steps"
        )
    check_samples(periods, samples_per_period, system.n)
    if not math.isfinite(system.omega) or system.omega <= 0:
        raise ValueError(f"omega must be a positive number, got {system.omega:g}")
    if record.family != "casadi" and rtol < 100 * np.finfo(float).eps:
        raise ValueError(
            f"rtol {rtol:g} is below what SciPy honours (2.2e-14); use cvodes or a larger rtol"
        )
    if not (rtol > 0 and atol > 0):
        raise ValueError(f"tolerances must be > 0, got rtol={rtol}, atol={atol}")
    if req.transient_rtol is not None:
        check_transient_rtol(req.transient_rtol, record)


def simulate(
    system: System,
    x0=None,
    *,
    method: str | None = None,
    rtol: float = 1e-8,
    atol: float = 1e-10,
    transient: int = 300,
    periods: int = 100,
    samples_per_period: int = 64,
    t0: float = 0.0,
    steps_per_period: int = 512,
    max_step: float | None = None,
    bound: float = 1e3,
    on_invalid: str = "warn",
    transient_rtol: float | None = None,
) -> Trajectory:
    """Integrate ``system`` from ``x0`` and sample the response after a transient.

    Parameters
    ----------
    system : System
        The model and its parameter values.
    x0 : array_like, shape (n,), optional
        Initial state; default :func:`default_initial_state`.
    method : str, optional
        One of :data:`METHODS`; default the fastest that meets ``rtol``.
    rtol, atol : float
        Tolerances of the adaptive methods (fixed-step ones use ``steps_per_period``).
    transient, periods : int
        Forcing periods discarded, then sampled.
    samples_per_period : int
        Samples per period in the window (a power of two suits the FFT).
    bound : float
        A state beyond this magnitude ends the run as ``divergent``.
    on_invalid : {"warn", "error"}
        What to do when a mesh coordinate leaves the force law's valid range (a
        polynomial fit, say): ``warn`` records the first exit (time, coordinate, value)
        and goes on; ``error`` stops there with status ``invalid`` (samples after the exit
        are not computed).
    transient_rtol : float, optional
        A looser relative tolerance for the transient alone (``atol`` scaled with it):
        the discarded periods only carry the state to the attractor, the sampled window
        is integrated at ``rtol`` from where they end.  A trade of speed for accuracy
        whose cost is measured in ``docs/body-models.md``; default: ``rtol`` throughout.
    """
    started = time.perf_counter()
    req = _request(
        system,
        x0,
        method,
        rtol,
        atol,
        transient,
        periods,
        samples_per_period,
        t0,
        steps_per_period,
        max_step,
        bound,
        on_invalid,
        transient_rtol,
    )
    backend = _backend(get_method(req.method).family)
    if req.transient_rtol is not None and req.transient > 0:
        return _trajectory(system, req, two_runs(backend, system, req), started)
    return _trajectory(system, req, backend(system, req), started)


def simulate_many(systems, x0s=None, *, workers: int = 1, **options) -> list[Trajectory]:
    """:func:`simulate` for many parameter points of one model, with the same options.

    The compiled methods integrate all points in one call of the lockstep engine
    (``native.run_batch``; ``workers`` processes); the others run :func:`simulate` point
    by point.  Trajectory ``i`` is what ``simulate(systems[i], x0s[i], **options)`` gives,
    up to the step sequence the group shares (so within the tolerance).
    """
    systems = list(systems)
    x0s = [None] * len(systems) if x0s is None else list(x0s)
    if len(x0s) != len(systems):
        raise ValueError(f"{len(systems)} systems but {len(x0s)} initial states")
    if not systems:
        return []
    method = options.get("method") or fastest_method(options.get("rtol", 1e-8))
    if get_method(method).family != "native" or len({s.module for s in systems}) != 1:
        return [simulate(s, x, **options) for s, x in zip(systems, x0s, strict=True)]
    started = time.perf_counter()
    keys = (
        "rtol",
        "atol",
        "transient",
        "periods",
        "samples_per_period",
        "t0",
        "steps_per_period",
        "max_step",
        "bound",
        "on_invalid",
        "transient_rtol",
    )
    defaults = (1e-8, 1e-10, 300, 100, 64, 0.0, 512, None, 1e3, "warn", None)
    unknown = set(options) - set(keys) - {"method"}
    if unknown:
        raise TypeError(f"unknown option(s) {sorted(unknown)}")
    args = [options.get(k, d) for k, d in zip(keys, defaults, strict=True)]
    reqs = [_request(s, x, method, *args) for s, x in zip(systems, x0s, strict=True)]
    from .native import run_many

    if reqs[0].transient_rtol is not None and reqs[0].transient > 0:
        runs = two_runs_many(run_many, systems, reqs, workers)
    else:
        runs = run_many(systems, reqs, workers=workers)
    return [_trajectory(s, q, r, started) for s, q, r in zip(systems, reqs, runs, strict=True)]


def _request(
    system,
    x0,
    method,
    rtol,
    atol,
    transient,
    periods,
    samples_per_period,
    t0,
    steps_per_period,
    max_step,
    bound,
    on_invalid,
    transient_rtol=None,
) -> Request:
    """The checked request of one run, with its initial state and sample grid."""
    if method is None:
        method = fastest_method(rtol)
    req = Request(
        x0=None,
        t0=t0,
        grid=None,
        method=method,
        rtol=rtol,
        atol=atol,
        transient=transient,
        periods=periods,
        samples_per_period=samples_per_period,
        steps_per_period=steps_per_period,
        max_step=max_step,
        bound=bound,
        on_invalid=on_invalid,
        transient_rtol=transient_rtol,
    )
    _check(system, req)
    if x0 is None:
        check_start(system)
        x0 = default_initial_state(system)
    x0 = np.asarray(x0, dtype=float)
    if x0.shape != (system.n,) or not np.all(np.isfinite(x0)):
        raise ValueError(f"x0 must be {system.n} finite numbers ({', '.join(system.states)})")
    check_start(system, x0)
    T = system.period
    t_start = t0 + transient * T
    grid = t_start + T * np.arange(periods * samples_per_period + 1) / samples_per_period
    return replace(req, x0=x0, grid=grid)


def _trajectory(system, req: Request, run, started: float) -> Trajectory:
    """A back end's run as a Trajectory: the valid range, the window, the bound."""
    grid, method, bound = req.grid, req.method, req.bound
    x, status, message = run.x, run.status, run.message
    exit_ = run.left_valid_range
    if exit_ is None:
        exit_ = first_exit(system, grid, x)
    if exit_ is not None and req.on_invalid == "error" and status == "ok":
        t_x, c_x, v_x = exit_
        x[:, grid > t_x] = np.nan
        status = "invalid"
        bound_c = system.contract.valid_range[c_x]
        message = (
            f"{c_x} = {v_x:.6g} at tau = {t_x:.6g} is outside the backlash model's "
            f"valid range |{c_x}| <= {bound_c:g}"
        )
    x_final = x[:, -1].copy()
    # Keep the window without its closing sample: exactly `periods` whole periods.
    t_out, x_out = grid[:-1], x[:, :-1]
    if status != "invalid":
        status, message = _check_bound(t_out, x_out, status, message, bound)
    fixed = not get_method(method).adaptive

    return Trajectory(
        system=system,
        method=method,
        rtol=req.rtol,
        atol=req.atol,
        transient=req.transient,
        periods=req.periods,
        samples_per_period=req.samples_per_period,
        t=t_out,
        x=x_out,
        x_final=x_final,
        t_final=float(grid[-1]),
        status=status,
        message=message,
        nfev=run.nfev,
        nsteps=run.nsteps,
        wall_time=time.perf_counter() - started,
        boundary_crossings=run.crossings,
        left_valid_range=exit_,
        options={"steps_per_period": req.steps_per_period} if fixed else said(req),
    )


def _backend(family: str):
    if family == "scipy":
        from .scipy_backend import run
    elif family == "casadi":
        from .casadi_backend import run
    else:
        from .native import run
    return run


def _check_bound(t, x, status, message, bound):
    if status != "ok":
        return status, message
    # In blocks of samples: a long run's temporaries stay small (issue 14).
    for k0 in range(0, x.shape[1], _BLOCK):
        xb = x[:, k0 : k0 + _BLOCK]
        bad = ~np.all(np.isfinite(xb) & (np.abs(xb) <= bound), axis=0)
        if np.any(bad):
            k = k0 + int(np.argmax(bad))
            return "divergent", f"a state passed |x| = {bound:g} by tau = {t[k]:.6g}"
    return status, message


_BLOCK = 1 << 16
