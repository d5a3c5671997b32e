"""The one event loop: SciPy integration that stops and restarts at switching surfaces.

A piecewise force law (the exact dead zone) has kinks on the surfaces ``x[i] = c`` that
the model's contract lists.  The vector field stays continuous there, but a Runge-Kutta
step across a kink loses its order; so every back end that locates surfaces integrates
with :func:`integrate_located`: ``solve_ivp`` with one terminal event per surface, a
restart on the surface, and the surface the state sits on shifted a hair behind the
motion so that it does not fire again at once but does fire on the way back.  A start
that cannot leave a surface is detected (stall) and reported instead of looping.

``simulate`` (sampled responses) and the flow map of ``solver/periodic`` (end states and
fundamental matrices) both use this loop.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

__all__ = [
    "LocatedRun",
    "SimulationError",
    "escape_event",
    "integrate_located",
    "surface_events",
]

_HAIR = 1e-10  # how far behind the motion a surface the state sits on is moved
_ON = 1e-9  # a state this close to a surface sits on it


class SimulationError(RuntimeError):
    """An integration could not be carried out (bad options or a failed solver)."""


@dataclass(frozen=True)
class LocatedRun:
    """How a located integration ended.

    ``stopped`` is None when ``t_end`` was reached, else the index (into ``extra``) of
    the terminal extra event that stopped it, with its time and state.
    """

    t: float
    y: np.ndarray
    stopped: int | None
    t_event: float | None
    y_event: np.ndarray | None
    nfev: int
    nsteps: int
    crossings: int


def surface_events(surfaces: Sequence[tuple[int, float]], offset: dict[int, float]) -> list:
    """Terminal zero-crossing functions ``x[i] - c + offset`` of the surfaces."""

    def make(i: int, edge: float, shift: float):
        def event(t, y):
            return y[i] - edge + shift

        event.terminal = True
        return event

    return [make(i, c, offset.get(k, 0.0)) for k, (i, c) in enumerate(surfaces)]


def escape_event(bound: float):
    """Terminal event: zero where the largest state magnitude reaches ``bound``."""

    def escape(t, y):
        return bound - np.max(np.abs(y))

    escape.terminal = True
    return escape


def integrate_located(
    fun: Callable,
    t0: float,
    t_end: float,
    y0: np.ndarray,
    *,
    surfaces: Sequence[tuple[int, float]],
    velocity: Callable[[int], int | None],
    method: str = "DOP853",
    options: dict | None = None,
    extra: Callable[[], list] | None = None,
    on_segment: Callable | None = None,
    dense: bool = False,
    max_restarts: int = 1_000_000,
) -> LocatedRun:
    """Integrate ``y' = fun(t, y)`` from ``t0`` to ``t_end``, restarting on every surface.

    Parameters
    ----------
    surfaces : sequence of (int, float)
        The switching surfaces ``y[i] = c`` (the contract's), in a fixed order.
    velocity : callable
        ``velocity(i)``: index of the time derivative of ``y[i]`` (sets which side of a
        surface the motion leaves to).
    options : dict
        Passed to ``solve_ivp`` (``rtol``, ``atol``, ``jac``, ``max_step``).
    extra : callable, optional
        Returns the extra events (after the surfaces) for the next segment; a terminal
        one that fires ends the run (``LocatedRun.stopped``).
    on_segment : callable, optional
        ``on_segment(t_start, sol)`` after every ``solve_ivp`` segment (dense output with
        ``dense``), e.g. to sample it.

    Raises
    ------
    SimulationError
        The solver failed, or the state cannot leave a surface.
    """
    from scipy.integrate import solve_ivp  # SciPy loads only when a run needs it

    options = options or {}
    t, y = float(t0), np.array(y0, dtype=float)
    nfev = nsteps = crossings = stalls = 0
    offset: dict[int, float] = {}
    ns = len(surfaces)
    for _ in range(max_restarts):
        events = surface_events(surfaces, offset) + (extra() if extra else [])
        sol = solve_ivp(
            fun, (t, t_end), y, method=method, dense_output=dense, events=events, **options
        )
        nfev += sol.nfev
        if sol.status == -1:
            raise SimulationError(f"{method} failed at tau = {t:.6g}: {sol.message}")
        if on_segment is not None:
            on_segment(t, sol)
        nsteps += sol.t.size - 1
        if sol.status == 0:
            return LocatedRun(
                float(sol.t[-1]), sol.y[:, -1], None, None, None, nfev, nsteps, crossings
            )
        k = next(k for k, te in enumerate(sol.t_events) if te.size)
        t_e, y_e = float(sol.t_events[k][0]), sol.y_events[k][0]
        if k >= ns:
            return LocatedRun(t_e, y_e, k - ns, t_e, y_e, nfev, nsteps, crossings)
        offset = {}
        for b, (i, edge) in enumerate(surfaces):
            if abs(y_e[i] - edge) <= _ON:
                j = velocity(i)
                speed = 0.0 if j is None else y_e[j]
                offset[b] = math.copysign(_HAIR, speed) if speed != 0 else _HAIR
        if t_e <= t:
            stalls += 1
            if stalls > 2 * ns:
                raise SimulationError(
                    f"{method} cannot leave the switching surface at tau = {t:.6g}: the "
                    "state stays on it; start from another state"
                )
        else:
            stalls = 0
        t, y = t_e, y_e
        crossings += 1
    raise SimulationError(f"more than {max_restarts} switching-surface crossings in one run")
