"""A looser tolerance for the transient (``simulate(..., transient_rtol=...)``).

The transient only carries the state to the attractor: it is run as a window of its own,
sampled once a period at the looser tolerance (``atol`` scaled with it), and the sampled
window from where it ended at ``rtol``.  The result is one trajectory whose work counts
both runs and whose ``options`` say the transient's tolerances.  What the trade buys and
costs is measured in ``benchmarks/body_models.py`` (``docs/body-models.md``).
"""

from __future__ import annotations

import math
import time
from dataclasses import replace

import numpy as np

from .trajectory import Trajectory

__all__ = ["two_tolerances", "two_tolerances_many"]


def _transient_options(options: dict, transient_rtol) -> dict:
    """The options of the transient's own run (checked ``transient_rtol``); ``options``
    name the method."""
    rtol = options.get("rtol", 1e-8)
    try:
        value = float(transient_rtol)
    except (TypeError, ValueError):
        value = math.nan
    if not (0 < value <= 0.1 and math.isfinite(value)):
        raise ValueError(f"transient_rtol must be a positive number <= 0.1, got {transient_rtol!r}")
    return dict(
        options,
        rtol=value,
        atol=options.get("atol", 1e-10) * value / rtol,
        transient=0,
        periods=options.get("transient", 300),
        samples_per_period=1,
    )


def two_tolerances(simulate, system, x0, options: dict, transient_rtol) -> Trajectory:
    """``simulate(system, x0, **options)`` with the transient at ``transient_rtol``
    (``simulate`` passed in: this module is below the front door it serves)."""
    started = time.perf_counter()
    first_options = _transient_options(options, transient_rtol)
    first = simulate(system, x0, **first_options)
    window = dict(options, transient=0, t0=first.t_final)
    second = simulate(system, first.x_final, **window) if first.status == "ok" else None
    return _joined(system, first, options, first_options, started, second)


def two_tolerances_many(
    simulate_many, systems, x0s, workers, options, transient_rtol
) -> list[Trajectory]:
    """``simulate_many`` alike, the windows of points whose transients ended together in
    one batch."""
    started = time.perf_counter()
    first_options = _transient_options(options, transient_rtol)
    firsts = simulate_many(systems, x0s, workers=workers, **first_options)
    # the windows in one batch per start time (a batch shares t0: points with one period)
    groups: dict[float, list[int]] = {}
    for i, f in enumerate(firsts):
        if f.status == "ok":
            groups.setdefault(f.t_final, []).append(i)
    seconds: dict[int, Trajectory] = {}
    for t_final, rows in groups.items():
        window = dict(options, transient=0, t0=t_final)
        done = simulate_many(
            [systems[i] for i in rows],
            [firsts[i].x_final for i in rows],
            workers=workers,
            **window,
        )
        seconds.update(zip(rows, done, strict=True))
    return [
        _joined(s, f, options, first_options, started, seconds.get(i))
        for i, (s, f) in enumerate(zip(systems, firsts, strict=True))
    ]


def _joined(system, first, options, first_options, started, second) -> Trajectory:
    """One trajectory of the transient's run ``first`` and the window's ``second`` (None
    when the transient failed: that fails the trajectory, its window NaN)."""
    said = {"transient_rtol": first_options["rtol"], "transient_atol": first_options["atol"]}
    transient, periods = options.get("transient", 300), options.get("periods", 100)
    if first.status != "ok":
        spp = options.get("samples_per_period", 64)
        T = system.period
        t = first.t_final + T * np.arange(periods * spp) / spp
        return replace(
            first,
            transient=transient,
            periods=periods,
            samples_per_period=spp,
            t=t,
            x=np.full((system.n, t.size), np.nan),
            x_final=np.full(system.n, np.nan),
            t_final=float(first.t_final + periods * T),
            rtol=options.get("rtol", 1e-8),
            atol=options.get("atol", 1e-10),
            wall_time=time.perf_counter() - started,
            options=dict(first.options, **said),
        )
    crossings = [c for c in (first.boundary_crossings, second.boundary_crossings) if c is not None]
    return replace(
        second,
        transient=transient,
        nfev=first.nfev + second.nfev,
        nsteps=first.nsteps + second.nsteps,
        boundary_crossings=sum(crossings) if crossings else None,
        left_valid_range=first.left_valid_range or second.left_valid_range,
        wall_time=time.perf_counter() - started,
        options=dict(second.options, **said),
    )
