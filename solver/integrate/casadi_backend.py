"""CasADi back end: ``cvodes`` (SUNDIALS, adaptive), ``rk`` (fixed-step RK4) and
``collocation`` (fixed-step Legendre collocation) on the model's CasADi graph."""

from __future__ import annotations

import re

import numpy as np

from .events import SimulationError
from .result import Request, Run, first_exit

__all__ = ["run"]


def run(system, req: Request) -> Run:
    import casadi as ca

    method, grid, t0 = req.method, req.grid, req.t0
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
            ends = np.asarray(F(x0=y, p=system.p)["xf"])
            work = _work(F, method)
            nfev, nsteps = nfev + work[0], nsteps + work[1]
            if not np.all(np.isfinite(ends)) or np.max(np.abs(ends)) > req.bound:
                ok = np.isfinite(ends) & (np.abs(ends) <= req.bound)
                bad = np.argmax(~np.all(ok, axis=0))
                out = np.full((system.n, grid.size), np.nan)
                message = f"a state passed |x| = {req.bound:g} in transient period {bad + 1}"
                return Run(out, "divergent", message, nfev, nsteps)
            exit_ = first_exit(system, ends_t, ends)
            y = ends[:, -1]
        window = int(round((grid[-1] - grid[0]) / T))
        F = ca.integrator("window", method, dae, grid[0], grid[1:], options(window))
        rest = np.asarray(F(x0=y, p=system.p)["xf"])
        work = _work(F, method)
        nfev, nsteps = nfev + work[0], nsteps + work[1]
    except RuntimeError as err:
        raise SimulationError(failure_message(method, str(err))) from None
    x = np.concatenate([y[:, None], rest], axis=1)
    return Run(x, "ok", "", nfev, nsteps, None, exit_)


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
