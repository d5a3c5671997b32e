"""Branch switching at a period doubling: from the period-n branch onto the period-2n one."""

from __future__ import annotations

import numpy as np

from ..integrate import simulate
from ..system import System
from .continuation import Bifurcation, Branch, continue_orbit
from .flow import FlowMap
from .shooting import ShootingError, shoot

__all__ = ["switch_period_doubling"]


def switch_period_doubling(
    system: System,
    parameter: str,
    bif: Bifurcation,
    n: int,
    stop: float,
    offset: float = 0.01,
    **kwargs,
) -> Branch:
    """Start the period-2n branch born at a period doubling and continue it toward
    ``stop``.

    A little past the bifurcation (``offset`` in the parameter) the new orbit lies about
    sqrt(offset) away along the eigenvector of the -1 multiplier.  It is looked for by
    simulation from there (a supercritical doubling gives a stable period-2n orbit) and
    then by shooting from guesses along the eigenvector on either side; an orbit counts
    only if it is not the period-n one.
    """
    sys = system.with_values(**{parameter: bif.value})
    _, M, _ = FlowMap(sys).with_jacobian(bif.x0, n * sys.period)
    w, V = np.linalg.eig(M)
    v = np.real(V[:, np.argmin(np.abs(w + 1.0))])
    v /= np.linalg.norm(v)
    toward = np.sign(stop - bif.value) or 1.0
    step = min(offset, abs(stop - bif.value) / 2 or offset)
    tried = []
    for side in (toward, -toward):
        lam = bif.value + side * step
        here = system.with_values(**{parameter: lam})
        guesses = []
        try:
            run = simulate(
                here, bif.x0 + np.sqrt(step) * v, method="cvodes", transient=300, periods=2 * n
            )
            if run.status == "ok":
                guesses.append((run.poincare[:, 0], run.t[0]))
        except (RuntimeError, ValueError):
            pass
        guesses += [(bif.x0 + s * np.sqrt(step) * v, 0.0) for s in (1.0, -1.0, 3.0, -3.0)]
        for guess, t0 in guesses:
            try:
                orbit = shoot(here, guess, 2 * n, t0=t0)
            except ShootingError as err:
                tried.append(str(err))
                continue
            half = FlowMap(here)(orbit.x0, n * here.period, orbit.t0)
            if np.max(np.abs(half - orbit.x0)) > 1e-6:
                x_start = orbit.x0
                if orbit.t0 % (2 * n * here.period) != 0:
                    # Continue with the section at tau = 0 (mod 2nT), like the parent branch.
                    x_start = FlowMap(here)(orbit.x0, (-orbit.t0) % (2 * n * here.period), orbit.t0)
                end = stop if side == toward else bif.value + side * abs(stop - bif.value)
                return continue_orbit(system, parameter, lam, end, x_start, n=2 * n, **kwargs)
    raise ShootingError(
        f"no period-{2 * n} orbit found next to the period doubling at "
        f"{parameter} = {bif.value:.6g}",
        tried,
    )
