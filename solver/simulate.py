"""One front door for time integration: ``simulate(system, ..., method=...)``.

Back ends by name (:data:`METHODS`):

* SciPy ``solve_ivp``: ``RK45`` (the reference study's variable-step Runge-Kutta 4(5),
  the default), ``DOP853``, ``LSODA``, ``Radau`` -- on the generated NumPy right-hand side
  (and its Jacobian for the implicit ones);
* CasADi ``integrator``: ``cvodes`` (SUNDIALS, adaptive), ``rk`` (fixed-step RK4 with
  ``steps_per_period`` steps), ``collocation`` (fixed-step implicit Legendre collocation)
  -- on the CasADi graph of the same equations;
* compiled (``solver/native.py``): ``dop853``, ``dopri5`` (SciPy's DOP853/RK45 step
  control in C on the generated C right-hand side) and ``rk4`` (fixed step,
  ``steps_per_period`` steps) -- the fastest; without a C compiler they fall back to NumPy
  with a warning.

The run is split into a transient of ``transient`` forcing periods, discarded, and a
sampled window of ``periods`` periods with ``samples_per_period`` samples each, aligned
with the forcing so that every ``samples_per_period``-th sample is a stroboscopic
(Poincare) point.  With the dead-zone backlash the SciPy back ends stop at every
contact-boundary crossing (``|u| = 1``) and restart there, so the method's order holds
across the kinks; the CasADi back ends rely on error control (cvodes) or a fine fixed step.

Every result records the method, the tolerances, the work done, and how the run ended.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import numpy as np
from scipy.integrate import solve_ivp

from .system import System

__all__ = ["METHODS", "SimulationError", "Trajectory", "fastest_method", "simulate"]

SCIPY_METHODS = ("RK45", "DOP853", "LSODA", "Radau")
CASADI_METHODS = ("cvodes", "rk", "collocation")
NATIVE_METHODS = ("dop853", "dopri5", "rk4")
METHODS = SCIPY_METHODS + CASADI_METHODS + NATIVE_METHODS


def fastest_method(rtol: float) -> str:
    """The fastest back end that meets ``rtol`` on this model class, from the measured
    speed/accuracy trade (``docs/performance.md``): compiled ``dop853`` (faster and more
    accurate than compiled ``dopri5`` at every tolerance measured, 1e-3 to 1e-12);
    ``cvodes``, the fastest uncompiled one, without a C compiler."""
    from .native import compiler

    del rtol  # one answer over the whole measured range; kept for the call's meaning
    return "cvodes" if compiler() is None else "dop853"


class SimulationError(RuntimeError):
    """An integration could not be carried out (bad options or a failed solver)."""


@dataclass(frozen=True)
class Trajectory:
    """A sampled response.

    Attributes
    ----------
    t : ndarray, shape (K,)
        Sample times (non-dimensional, tau) of the sampled window.
    x : ndarray, shape (n, K)
        States at ``t``.
    samples_per_period : int
        Samples per forcing period; ``x[:, ::samples_per_period]`` are Poincare points.
    status : str
        ``ok``, ``divergent`` (a state passed ``bound``) or ``failed``.
    """

    system: System
    method: str
    rtol: float
    atol: float
    transient: int
    periods: int
    samples_per_period: int
    t: np.ndarray
    x: np.ndarray
    x_final: np.ndarray
    t_final: float
    status: str
    message: str
    nfev: int
    nsteps: int
    wall_time: float
    boundary_crossings: int | None = None  # located crossings (SciPy back ends only)
    left_valid_range: tuple | None = None  # (tau, state, value) of the first exit
    options: dict = field(default_factory=dict)

    @property
    def period(self) -> float:
        return self.system.period

    @property
    def poincare(self) -> np.ndarray:
        """Stroboscopic points at the start of each sampled period, shape (n, periods)."""
        return self.x[:, : self.periods * self.samples_per_period : self.samples_per_period]

    def coordinate(self, name: str) -> np.ndarray:
        return self.x[self.system.index(name)]

    def describe(self) -> dict:
        return {
            "method": self.method,
            "rtol": self.rtol,
            "atol": self.atol,
            "transient_periods": self.transient,
            "sampled_periods": self.periods,
            "samples_per_period": self.samples_per_period,
            "status": self.status,
            "message": self.message,
            "nfev": self.nfev,
            "nsteps": self.nsteps,
            "wall_time_s": self.wall_time,
            "boundary_crossings": self.boundary_crossings,
            "left_valid_range": None
            if self.left_valid_range is None
            else dict(zip(("tau", "state", "value"), self.left_valid_range, strict=True)),
            "options": self.options,
        }


def simulate(
    system: System,
    x0=None,
    *,
    method: str = "RK45",
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
) -> Trajectory:
    """Integrate ``system`` from ``x0`` and sample the response after a transient.

    Parameters
    ----------
    system : System
        The model and its parameter values.
    x0 : array_like, shape (n,), optional
        Initial state; default: each coordinate at its static load (``u = 1 + f``
        roughly in contact), velocities zero.
    method : str
        One of :data:`METHODS`.
    rtol, atol : float
        Tolerances of the adaptive methods (``rk`` and ``collocation`` use
        ``steps_per_period`` instead).
    transient, periods : int
        Forcing periods discarded, then sampled.
    samples_per_period : int
        Samples per period in the window (a power of two suits the FFT).
    bound : float
        A state beyond this magnitude ends the run as ``divergent``.
    on_invalid : {"warn", "error"}
        What to do when a mesh coordinate leaves the backlash model's valid range (a
        polynomial fit, say): ``warn`` records the first exit (time, coordinate, value)
        and goes on; ``error`` stops there with status ``invalid`` (samples after the exit
        are not computed).
    """
    if method not in METHODS:
        raise ValueError(f"unknown method '{method}'; methods: {', '.join(METHODS)}")
    if on_invalid not in ("warn", "error"):
        raise ValueError(f"on_invalid must be 'warn' or 'error', got {on_invalid!r}")
    for name, value in (("transient", transient), ("periods", periods)):
        if not (isinstance(value, int) and value >= 0):
            raise ValueError(f"{name} must be a whole number >= 0, got {value!r}")
    if periods < 1 or samples_per_period < 1:
        raise ValueError("periods and samples_per_period must be >= 1")
    if not (isinstance(samples_per_period, int) and isinstance(steps_per_period, int)):
        raise ValueError("samples_per_period and steps_per_period must be whole numbers")
    unit = {"rk": 1, "rk4": 1, "collocation": 4}.get(method)
    if unit and (steps_per_period < unit * samples_per_period
                 or steps_per_period % (unit * samples_per_period)):  # fmt: skip
        raise ValueError(
            f"steps_per_period ({steps_per_period}) must be a multiple of "
            f"{'4 x ' if unit == 4 else ''}samples_per_period ({samples_per_period}) for "
            f"'{method}', so that every sample interval holds whole steps"
        )
    if not math.isfinite(system.omega) or system.omega <= 0:
        raise ValueError(f"omega must be a positive number, got {system.omega:g}")
    if method in SCIPY_METHODS + NATIVE_METHODS and rtol < 100 * np.finfo(float).eps:
        raise ValueError(f"rtol {rtol:g} is below what SciPy honours (2.2e-14); use cvodes "
                         "or a larger rtol")  # fmt: skip
    if not (rtol > 0 and atol > 0):
        raise ValueError(f"tolerances must be > 0, got rtol={rtol}, atol={atol}")
    x0 = default_initial_state(system) if x0 is None else np.asarray(x0, dtype=float)
    if x0.shape != (system.n,) or not np.all(np.isfinite(x0)):
        raise ValueError(f"x0 must be {system.n} finite numbers ({', '.join(system.states)})")
    T = system.period
    t_start = t0 + transient * T
    grid = t_start + T * np.arange(periods * samples_per_period + 1) / samples_per_period
    started = time.perf_counter()
    if method in SCIPY_METHODS:
        run = _scipy_run(system, x0, t0, grid, method, rtol, atol, max_step, bound, on_invalid)
    elif method in NATIVE_METHODS:
        run = _native_run(system, x0, t0, transient, periods, method, rtol, atol,
                          steps_per_period, samples_per_period, bound)  # fmt: skip
    else:
        run = _casadi_run(
            system, x0, t0, grid, method, rtol, atol, steps_per_period, samples_per_period, bound
        )
    x, status, message, nfev, nsteps, crossings, exit_ = run
    if exit_ is None:
        exit_ = _first_exit(system, grid, x)
    if exit_ is not None and on_invalid == "error" and status == "ok":
        t_x, c_x, v_x = exit_
        x[:, grid > t_x] = np.nan
        status = "invalid"
        message = (f"{c_x} = {v_x:.6g} at tau = {t_x:.6g} is outside the backlash model's "
                   f"valid range |{c_x}| <= {system.valid_range:g}")  # fmt: skip
    x_final = x[:, -1].copy()
    # Keep the window without its closing sample: exactly `periods` whole periods.
    t_out, x_out = grid[:-1], x[:, :-1]
    if status != "invalid":
        status, message = _check_bound(t_out, x_out, status, message, bound)
    return Trajectory(
        system=system,
        method=method,
        rtol=rtol,
        atol=atol,
        transient=transient,
        periods=periods,
        samples_per_period=samples_per_period,
        t=t_out,
        x=x_out,
        x_final=x_final,
        t_final=float(grid[-1]),
        status=status,
        message=message,
        nfev=nfev,
        nsteps=nsteps,
        wall_time=time.perf_counter() - started,
        boundary_crossings=crossings,
        left_valid_range=exit_,
        options=(
            {"steps_per_period": steps_per_period} if method in ("rk", "rk4", "collocation") else {}
        ),
    )


def default_initial_state(system: System) -> np.ndarray:
    """Each coordinate pressed into contact by its load (``u = 1 + f`` with the sign of
    ``f``), at rest: close to the loaded equilibrium for ``g`` near the dead zone."""
    x0 = np.zeros(system.n)
    names = set(system.module.PARAMETERS)
    for i, c in enumerate(system.coordinates):
        f = system.parameter(f"f_{c}") if f"f_{c}" in names else 0.0
        x0[i] = math.copysign(1.0, f) + f if f != 0 else 0.0
    return x0


def _check_bound(t, x, status, message, bound):
    if status != "ok":
        return status, message
    bad = ~np.all(np.isfinite(x) & (np.abs(x) <= bound), axis=0)
    if np.any(bad):
        k = int(np.argmax(bad))
        return "divergent", f"a state passed |x| = {bound:g} by tau = {t[k]:.6g}"
    return status, message


def _first_exit(system: System, t, x):
    a = system.valid_range
    if a is None:
        return None
    m = len(system.coordinates)
    out = np.abs(x[:m]) > a * (1 + 1e-12)
    if not np.any(out):
        return None
    k = int(np.argmax(np.any(out, axis=0)))
    i = int(np.argmax(out[:, k]))
    return float(t[k]), system.coordinates[i], float(x[i, k])


# -- SciPy -------------------------------------------------------------------------------


def _scipy_run(system, x0, t0, grid, method, rtol, atol, max_step, bound, on_invalid="warn"):
    fun = system.rhs
    opts = {"rtol": rtol, "atol": atol}
    if method in ("Radau", "LSODA"):
        opts["jac"] = system.jacobian
    if max_step is not None:
        opts["max_step"] = max_step
    boundaries = _boundaries(system) if system.backlash == "dead-zone" else []
    x = np.full((system.n, grid.size), np.nan)
    t, y = t0, np.array(x0, dtype=float)
    nfev = nsteps = crossings = stalls = 0
    offset: dict[int, float] = {}
    t_end = grid[-1]
    exit_ = None
    valid = _valid_event(system, terminal=on_invalid == "error")
    while True:
        events = [_boundary_event(i, edge, offset.get(k, 0.0))
                  for k, (i, edge) in enumerate(boundaries)] + [_escape_event(bound)]  # fmt: skip
        if valid is not None and (exit_ is None or on_invalid == "error"):
            events.append(valid)
        sol = solve_ivp(fun, (t, t_end), y, method=method, dense_output=True, events=events,
                        **opts)  # fmt: skip
        nfev += sol.nfev
        if sol.status == -1:
            raise SimulationError(f"{method} failed at tau = {t:.6g}: {sol.message}")
        if valid is not None and exit_ is None and len(sol.t_events) > len(boundaries) + 1:
            hits = sol.t_events[len(boundaries) + 1]
            if hits.size:
                y_x = sol.y_events[len(boundaries) + 1][0]
                i = int(np.argmax(np.abs(y_x[: len(system.coordinates)])))
                exit_ = (float(hits[0]), system.coordinates[i], float(y_x[i]))
        nsteps += sol.t.size - 1
        # Samples that fall in this segment, from the method's own dense output.
        lo = np.searchsorted(grid, t, side="left")
        hi = np.searchsorted(grid, sol.t[-1], side="right")
        if hi > lo:
            x[:, lo:hi] = sol.sol(grid[lo:hi])
        if sol.status == 0:
            return x, "ok", "", nfev, nsteps, crossings, exit_
        k = next(k for k, te in enumerate(sol.t_events) if te.size)
        if k == len(boundaries) + 1:  # left the valid range, with on_invalid="error"
            return x, "ok", "", nfev, nsteps, crossings, exit_
        t_e, y_e = float(sol.t_events[k][0]), sol.y_events[k][0]
        if k == len(boundaries):
            message = f"a state passed |x| = {bound:g} at tau = {t_e:.6g}"
            return x, "divergent", message, nfev, nsteps, crossings, exit_
        # Restart on the contact boundary.  Every boundary the state sits on (the one just
        # crossed, and any other within a hair) is shifted a hair behind the motion, so
        # that it does not fire again at once but does fire on the way back.
        m = len(system.coordinates)
        offset = {}
        for b, (i, edge) in enumerate(boundaries):
            if abs(y_e[i] - edge) <= 1e-9:
                offset[b] = math.copysign(1e-10, y_e[m + i]) if y_e[m + i] != 0 else 1e-10
        if t_e <= t:
            stalls += 1
            if stalls > 2 * len(boundaries):
                raise SimulationError(
                    f"{method} cannot leave the contact boundary at tau = {t:.6g}: the state "
                    "stays on |u| = 1; start from another state"
                )
        else:
            stalls = 0
        t, y = t_e, y_e
        crossings += 1


def _boundaries(system: System) -> list[tuple[int, float]]:
    return [(i, edge) for i in range(len(system.coordinates)) for edge in (1.0, -1.0)]


def _boundary_event(i: int, edge: float, offset: float):
    def event(t, y):
        return y[i] - edge + offset

    event.terminal = True
    return event


def _valid_event(system: System, terminal: bool):
    """Zero where a mesh coordinate reaches the backlash model's valid range (None if the
    model is valid everywhere)."""
    a = system.valid_range
    if a is None:
        return None
    m = len(system.coordinates)

    def valid(t, y):  # touching the edge of the range is still inside it
        return a * (1 + 1e-12) - np.max(np.abs(y[:m]))

    valid.terminal = terminal
    valid.direction = -1
    return valid


def _escape_event(bound: float):
    def escape(t, y):
        return bound - np.max(np.abs(y))

    escape.terminal = True
    return escape


# -- CasADi ------------------------------------------------------------------------------


def _casadi_run(system, x0, t0, grid, method, rtol, atol, steps, spp, bound):
    import casadi as ca

    f, _ = system.casadi
    tau = ca.SX.sym("tau")
    xs = ca.SX.sym("x", system.n)
    ps = ca.SX.sym("p", system.p.size)
    dae = {"x": xs, "p": ps, "t": tau, "ode": f(tau, xs, ps)}
    T = system.period

    # Failures are reported once, as a SimulationError; CasADi's and SUNDIALS's own
    # per-step warnings would only flood the terminal.
    quiet = {"show_eval_warnings": False}

    def options(periods: int) -> dict:
        if method == "cvodes":
            return quiet | {"reltol": rtol, "abstol": atol, "max_num_steps": 1_000_000,
                            "disable_internal_warnings": True}  # fmt: skip
        # CasADi spreads number_of_finite_elements over the whole horizon, so it is
        # `steps` per forcing period times the periods covered (collocation: elements of
        # four points each, i.e. steps / 4 elements per period).
        per_period = steps if method == "rk" else steps // 4
        opts = quiet | {"number_of_finite_elements": per_period * periods}
        if method == "collocation":
            opts["interpolation_order"] = 4
            opts["rootfinder_options"] = {"error_on_fail": True}
        return opts

    nfev = nsteps = 0
    exit_ = None
    try:
        y = np.asarray(x0, dtype=float)
        transient = int(round((grid[0] - t0) / T))
        if transient > 0:
            F = ca.integrator("transient", method, dae, t0, t0 + T * np.arange(1, transient + 1),
                              options(transient))  # fmt: skip
            ends = np.asarray(F(x0=y, p=system.p)["xf"])
            work = _casadi_work(F, method)
            nfev, nsteps = nfev + work[0], nsteps + work[1]
            if not np.all(np.isfinite(ends)) or np.max(np.abs(ends)) > bound:
                bad = np.argmax(~np.all(np.isfinite(ends) & (np.abs(ends) <= bound), axis=0))
                out = np.full((system.n, grid.size), np.nan)
                message = f"a state passed |x| = {bound:g} in transient period {bad + 1}"
                return out, "divergent", message, nfev, nsteps, None, None
            exit_ = _first_exit(system, t0 + T * np.arange(1, transient + 1), ends)
            y = ends[:, -1]
        window = int(round((grid[-1] - grid[0]) / T))
        F = ca.integrator("window", method, dae, grid[0], grid[1:], options(window))
        rest = np.asarray(F(x0=y, p=system.p)["xf"])
        work = _casadi_work(F, method)
        nfev, nsteps = nfev + work[0], nsteps + work[1]
    except RuntimeError as err:
        raise SimulationError(_casadi_failure(method, str(err))) from None
    x = np.concatenate([y[:, None], rest], axis=1)
    return x, "ok", "", nfev, nsteps, None, exit_


def _native_run(system, x0, t0, transient, periods, method, rtol, atol, steps, spp, bound):
    from .native import run_batch

    res = run_batch(system.module, system.p[None, :], np.asarray(x0, float)[None, :],
                    method=method, rtol=rtol, atol=atol, t0=t0, transient=transient,
                    periods=periods, samples_per_period=spp, steps_per_period=steps,
                    bound=bound, lockstep=False)  # fmt: skip
    x = res.x[0].T.copy()
    status = res.status[0]
    nfev, nsteps = int(res.nfev[0]), int(res.nsteps[0])
    if status == "ok":
        return x, "ok", "", nfev, nsteps, None, None
    t_fail = float(res.t_fail[0])
    if status == "divergent":
        return (
            x,
            "divergent",
            f"a state passed |x| = {bound:g} at tau = {t_fail:.6g}",
            nfev,
            nsteps,
            None,
            None,
        )
    return (
        x,
        "failed",
        f"{method} stopped at tau = {t_fail:.6g}: {status}",
        nfev,
        nsteps,
        None,
        None,
    )


def _casadi_failure(method: str, text: str) -> str:
    """One readable line from a CasADi/SUNDIALS error (no source paths)."""
    import re

    flag = re.search(r"\b(CV_[A-Z_]+)\b", text)
    if flag:
        why = {
            "CV_TOO_MUCH_WORK": "too many steps: the state may be growing without bound, "
            "or the problem needs another method",
            "CV_CONV_FAILURE": "the corrector did not converge (a stiff or diverging run)",
            "CV_ERR_FAILURE": "the error test failed repeatedly (a kink or a blow-up)",
        }
        return f"{method} stopped ({flag.group(1)}): {why.get(flag.group(1), 'see SUNDIALS')}"
    if "rootfinder" in text:
        return (f"{method}: the Newton iteration inside a collocation step failed; use more "
                "steps per period or another method")  # fmt: skip
    last = [ln for ln in text.strip().splitlines() if ln.strip()][-1]
    return f"{method} failed: {last.split(': ')[-1][:160]}"


def _casadi_work(F, method: str) -> tuple[int, int]:
    """(right-hand side evaluations, steps) from a CasADi integrator's statistics."""
    try:
        stats = F.stats()
    except RuntimeError:
        return 0, 0
    if method == "cvodes":
        return int(stats.get("nfevals", 0)), int(stats.get("nsteps", 0))
    steps = int(stats.get("n_call_step", 0))
    # RK4 evaluates the right-hand side four times a step; a collocation step solves for
    # its four points with Newton, whose evaluations CasADi does not count separately.
    return (4 * steps if method == "rk" else 0), steps
