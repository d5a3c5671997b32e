"""CasADi back end: ``cvodes`` (SUNDIALS, adaptive), ``rk`` (fixed-step RK4) and
``collocation`` (fixed-step Legendre collocation) on the model's CasADi graph."""

from __future__ import annotations

import contextlib
import os
import re

import numpy as np

from .events import SimulationError
from .result import Request, Run, first_exit

__all__ = ["run"]


def run(system, req: Request) -> Run:
    # CasADi prints a failing step's inputs to the C stderr before raising; the failure
    # is reported once, as one line, from the exception's text.
    with _quiet_c_stderr():
        return _run(system, req)


@contextlib.contextmanager
def _quiet_c_stderr():
    import sys

    sys.stderr.flush()
    try:
        saved = os.dup(2)
    except OSError:  # no file descriptor 2 (an embedded interpreter): nothing to hide
        yield
        return
    try:
        with open(os.devnull, "w") as null:
            os.dup2(null.fileno(), 2)
        yield
    finally:
        os.dup2(saved, 2)
        os.close(saved)


def _run(system, req: Request) -> Run:
    import casadi as ca

    method, grid, t0 = req.method, req.grid, req.t0
    f, _ = system.casadi
    tau = ca.SX.sym("tau")
    xs = ca.SX.sym("x", system.n)
    ps = ca.SX.sym("p", system.p.size)
    dae = {"x": xs, "p": ps, "t": tau, "ode": f(tau, xs, ps)}
    bounds = system.contract.valid_bounds()
    if bounds:
        # The integral of how far the state is outside its valid range: it grows on any
        # interval holding an exit, however short, so no exit hides between outputs.
        dae["quad"] = sum(ca.fmax(0, ca.fabs(xs[i]) - b) for i, b in bounds)
    T = system.period
    # Failures are reported once, as a SimulationError; CasADi's and SUNDIALS's own
    # per-step warnings would only flood the terminal.
    quiet = {"show_eval_warnings": False}

    def options(periods: int) -> dict:
        if method == "cvodes":
            return quiet | {
                "reltol": req.rtol,
                "abstol": req.atol,
                "max_num_steps": 1_000_000,
                "disable_internal_warnings": True,
            }
        # CasADi spreads number_of_finite_elements over the whole horizon, so it is
        # `steps` per forcing period times the periods covered (collocation: elements of
        # four points each, i.e. steps / 4 elements per period).
        steps = req.steps_per_period
        per_period = steps if method == "rk" else steps // 4
        opts = quiet | {"number_of_finite_elements": per_period * periods}
        if method == "collocation":
            opts["interpolation_order"] = 4
            opts["rootfinder_options"] = {"error_on_fail": True}
        return opts

    nfev = nsteps = 0
    exit_ = None
    try:
        y = np.asarray(req.x0, dtype=float)
        transient = int(round((grid[0] - t0) / T))
        if transient > 0:
            ends_t = t0 + T * np.arange(1, transient + 1)
            F = ca.integrator("transient", method, dae, t0, ends_t, options(transient))
            res = F(x0=y, p=system.p)
            ends = np.asarray(res["xf"])
            work = _work(F, method)
            nfev, nsteps = nfev + work[0], nsteps + work[1]
            if not np.all(np.isfinite(ends)) or np.max(np.abs(ends)) > req.bound:
                ok = np.isfinite(ends) & (np.abs(ends) <= req.bound)
                bad = np.argmax(~np.all(ok, axis=0))
                out = np.full((system.n, grid.size), np.nan)
                message = f"a state passed |x| = {req.bound:g} in transient period {bad + 1}"
                return Run(out, "divergent", message, nfev, nsteps)
            exit_ = _located(system, dae, method, req.x0, t0, ends_t, ends, res, options)
            y = ends[:, -1]
        window = int(round((grid[-1] - grid[0]) / T))
        F = ca.integrator("window", method, dae, grid[0], grid[1:], options(window))
        res = F(x0=y, p=system.p)
        rest = np.asarray(res["xf"])
        work = _work(F, method)
        nfev, nsteps = nfev + work[0], nsteps + work[1]
        if exit_ is None:
            exit_ = _located(system, dae, method, y, grid[0], grid[1:], rest, res, options)
    except RuntimeError as err:
        # The same event gives the same status from every method: a run that stopped
        # because the state grew past the bound is "divergent", as with the others.
        diverged = _diverged(
            system,
            dae,
            method,
            np.asarray(req.x0, float),
            t0,
            T,
            int(round((grid[-1] - t0) / T)),
            req.bound,
            options,
        )
        if diverged is None:
            raise SimulationError(failure_message(method, str(err))) from None
        out = np.full((system.n, grid.size), np.nan)
        return Run(out, "divergent", diverged, nfev, nsteps, None, exit_)
    x = np.concatenate([y[:, None], rest], axis=1)
    return Run(x, "ok", "", nfev, nsteps, None, exit_)


def _diverged(system, dae, method, x0, t0, T, periods, bound, options) -> str | None:
    """After a failed integration: the message of the period in which the state passed
    ``bound`` (integrating period by period, at most 200 periods, until the failure), or
    None when it failed with the state bounded."""
    import casadi as ca

    sub = {key: v for key, v in dae.items() if key != "quad"}
    y = x0
    for k in range(min(periods, 200)):
        try:
            F = ca.integrator("scan", method, sub, t0 + k * T, t0 + (k + 1) * T, options(1))
            y = np.asarray(F(x0=y, p=system.p)["xf"]).ravel()
        except RuntimeError:
            y = None
        if y is None:
            return None  # failed with the state still bounded
        if not np.all(np.isfinite(y)) or np.max(np.abs(y)) > bound:
            return f"a state passed |x| = {bound:g} in period {k + 1}"
    return None


def _located(system, dae, method, x_start, t_start, ends_t, ends, res, options):
    """(tau, state, value) of the first exit from the valid range between ``t_start`` and
    ``ends_t[-1]``: the first output interval whose excess integral grew (or whose end is
    outside) is integrated again on 512 sub-intervals and the crossing interpolated."""
    import casadi as ca

    if "quad" not in dae:
        return None
    qf = np.concatenate([[0.0], np.asarray(res["qf"]).ravel()])
    k = np.flatnonzero(np.diff(qf) > 0)
    coarse = first_exit(system, ends_t, ends)
    candidates = [int(k[0])] if k.size else []
    if coarse is not None:
        candidates.append(int(np.searchsorted(ends_t, coarse[0])))
    if not candidates:
        return None
    j = min(candidates)
    ta = t_start if j == 0 else float(ends_t[j - 1])
    xa = np.asarray(x_start, float) if j == 0 else ends[:, j - 1]
    fine = np.linspace(ta, float(ends_t[j]), 513)
    sub = {key: v for key, v in dae.items() if key != "quad"}
    F = ca.integrator("locate", method, sub, ta, fine[1:], options(1))
    xs = np.concatenate([xa[:, None], np.asarray(F(x0=xa, p=system.p)["xf"])], axis=1)
    hit = first_exit(system, fine, xs)
    if hit is None:
        return coarse
    t_hit, state, _ = hit
    i = system.index(state)
    m = int(np.searchsorted(fine, t_hit))
    b = dict(system.contract.valid_bounds())[i]
    a0, a1 = abs(xs[i, m - 1]), abs(xs[i, m])
    share = (b - a0) / (a1 - a0) if a1 != a0 else 1.0
    # the crossing's time interpolated; the value is the first one seen outside
    return float(fine[m - 1] + share * (fine[m] - fine[m - 1])), state, float(xs[i, m])


def failure_message(method: str, text: str) -> str:
    """One readable line from a CasADi/SUNDIALS error (no source paths)."""
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
        return (
            f"{method}: the Newton iteration inside a collocation step failed; use more "
            "steps per period or another method"
        )
    last = [ln for ln in text.strip().splitlines() if ln.strip()][-1]
    return f"{method} failed: {last.split(': ')[-1][:160]}"


def _work(F, method: str) -> tuple[int, int]:
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
