"""SciPy ``solve_ivp`` back end (RK45, scipy-dop853, LSODA, Radau) on the generated NumPy code.

Samples come from each method's own dense output; piecewise models run through the one
event loop (``events.py``) that stops at every switching surface.
"""

from __future__ import annotations

import numpy as np

from .events import escape_event, integrate_located
from .methods import get_method
from .result import Request, Run

__all__ = ["run"]


def run(system, req: Request) -> Run:
    contract = system.contract
    opts = {"rtol": req.rtol, "atol": req.atol}
    if req.method in ("Radau", "LSODA"):
        opts["jac"] = system.jacobian
    if req.max_step is not None:
        opts["max_step"] = req.max_step
    grid = req.grid
    x = np.full((system.n, grid.size), np.nan)
    exit_: list = [None]
    valid = _valid_event(system, terminal=req.on_invalid == "error")
    escape = escape_event(req.bound)

    def extra():
        events = [escape]
        if valid is not None and (exit_[0] is None or req.on_invalid == "error"):
            events.append(valid)
        return events

    def sample(t, sol):
        if valid is not None and exit_[0] is None and len(sol.t_events) > n_surf + 1:
            hits = sol.t_events[n_surf + 1]
            if hits.size:
                exit_[0] = _exit_at(system, float(hits[0]), sol.y_events[n_surf + 1][0])
        lo = np.searchsorted(grid, t, side="left")
        hi = np.searchsorted(grid, sol.t[-1], side="right")
        if hi > lo:
            x[:, lo:hi] = sol.sol(grid[lo:hi])

    surfaces = contract.switching_surfaces
    n_surf = len(surfaces)
    done = integrate_located(
        system.rhs,
        req.t0,
        grid[-1],
        req.x0,
        surfaces=surfaces,
        velocity=contract.velocity_of_state,
        method=get_method(req.method).engine,
        options=opts,
        extra=extra,
        on_segment=sample,
        dense=True,
    )
    out = Run(x, "ok", "", done.nfev, done.nsteps, done.crossings, exit_[0])
    if done.stopped == 0:  # the escape event
        out.status = "divergent"
        out.message = f"a state passed |x| = {req.bound:g} at tau = {done.t_event:.6g}"
    return out


def _exit_at(system, t: float, y) -> tuple:
    """(tau, coordinate, value) of the coordinate closest to (or past) its bound."""
    bounds = system.contract.valid_bounds()
    k = int(np.argmin([a - abs(y[i]) for i, a in bounds]))
    i = bounds[k][0]
    return t, system.states[i], float(y[i])


def _valid_event(system, terminal: bool):
    """Zero where a mesh coordinate reaches the force law's valid range (None if the
    model is valid everywhere); touching the edge of the range is still inside it."""
    bounds = system.contract.valid_bounds()
    if not bounds:
        return None
    idx = np.array([i for i, _ in bounds])
    a = np.array([b for _, b in bounds]) * (1 + 1e-12)

    def valid(t, y):
        return np.min(a - np.abs(y[idx]))

    valid.terminal = terminal
    valid.direction = -1
    return valid
