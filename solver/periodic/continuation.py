"""Continuation of periodic orbits by shooting: the problem on one stroboscopic map, and
its front door :func:`continue_orbit` on the engine of ``engine.py``.

Unknowns ``z = (x0, lambda)``: the orbit's state at tau = 0 (mod nT) and the parameter;

    ``G(x0, lambda) = phi_{nT}(x0; lambda) - x0``,

the stroboscopic map of ``flow.py`` minus the identity, with one flow map for the whole
branch (lambda changes only the parameter vector passed to it).  ``G_u`` is the monodromy
minus I, ``G_lambda`` a central difference (step ``1e-6 max(1, |lambda|)``, one-sided at
an end of the valid range), evaluated at every corrector iterate.  Stability: the Floquet
multipliers of the monodromy (``floquet.py``); test functions ``det(M - I)``,
``det(M + I)`` and the Neimark-Sacker product.  At a period doubling the branch can be
switched onto the period-2n orbit (``switching.py``).
"""

from __future__ import annotations

import time
from dataclasses import replace

import numpy as np

from ..integrate._quiet import quiet
from ..system import System
from ._bounds import interval_of
from .engine import Linearisation, Settings, continue_branch
from .floquet import Floquet, bifurcation_tests, floquet
from .flow import StroboscopicMap
from .records import Bifurcation, Branch, BranchPoint
from .shooting import shoot

__all__ = ["Bifurcation", "Branch", "ShootingProblem", "continue_orbit"]


def model_fields(system: System) -> dict:
    """The state names and the model (name, hash, base values, scales) a branch keeps."""
    return {
        "state_names": system.states,
        "model": {
            "model": system.name,
            "model_hash": system.model_hash,
            "base_values": {k: float(v) for k, v in system.values.items()},
            "scales": system.scales(),
        },
    }


class ShootingProblem:
    """``G(x0, lambda)``, its Jacobian and the orbit's stability for one branch of
    period-n orbits, on one stroboscopic map whose parameter vector follows lambda."""

    def __init__(self, system: System, parameter: str, n: int):
        self.base, self.parameter, self.n = system, parameter, n
        self.valid = interval_of(system, parameter)
        self.map = StroboscopicMap(system, n)

    def system(self, lam: float) -> System:
        if lam not in self.valid:
            raise ValueError(f"{self.parameter} = {lam:g} is outside {self.valid.rule()}")
        return self.base.with_values(**{self.parameter: float(lam)})

    def G(self, x, lam) -> np.ndarray:
        with quiet():  # CasADi's dump of a failed integration: the error says it
            return self.map(x, self.system(lam).p) - x

    def linearise(self, z, column=None) -> Linearisation:
        """G, ``G_u = M - I`` and ``G_lambda`` at ``z``; ``extra``: (M, int trace J)."""
        x, lam = z[:-1], z[-1]
        with quiet():
            # The variational equations on CVODES (located crossings for a piecewise
            # model): they agree with CasADi's forward sensitivities to about 1e-11
            # (flow.monodromy_agreement) at a quarter of the time on the reference model
            # (6 ms against 24 ms a period; 51 against 117 ms on the 22-state bearing
            # model).  The corrector's 1e-10 stays above their end state's noise; Newton
            # shooting's 1e-11 with its line search does not, and keeps AD.
            xe, M, q = self.map.jacobian(x, self.system(lam).p, method="variational")
        if column is None:
            h = 1e-6 * max(1.0, abs(lam))
            up, dn = lam + h, lam - h
            if up not in self.valid:
                up = lam
            elif dn not in self.valid:
                dn = lam
            column = (self.G(x, up) - self.G(x, dn)) / (up - dn)
        return Linearisation(xe - x, M - np.eye(M.shape[0]), column, (M, q))

    def frozen_column(self, z) -> None:
        return None

    def stability(self, z, lin: Linearisation) -> Floquet:
        return floquet(*lin.extra)

    def tests(self, z, lin: Linearisation, floquet: Floquet | None = None) -> np.ndarray:
        return bifurcation_tests(lin.extra[0])

    def multipliers(self, z, lin: Linearisation) -> np.ndarray:
        return np.linalg.eigvals(lin.extra[0])

    def state(self, z) -> np.ndarray:
        return z[:-1].copy()

    def point(self, z, sign: int, fl: Floquet | None) -> BranchPoint:
        return BranchPoint(
            float(z[-1]), z[:-1].copy(), fl.multipliers, fl.stable, fl.stability, sign
        )

    def solve_at(self, lam: float, guess, sign: int) -> BranchPoint:
        """Shoot at ``lam`` from ``guess`` (the damped Newton of shooting)."""
        orbit = shoot(self.system(lam), guess, self.n, flow=self.map.flow)
        fl = orbit.floquet
        return BranchPoint(
            float(lam), orbit.x0.copy(), fl.multipliers, fl.stable, fl.stability, sign
        )

    def evidence(self, z) -> dict:
        return {}

    def branch_fields(self) -> dict:
        return model_fields(self.base)


def continue_orbit(
    system: System,
    parameter: str,
    start: float,
    stop: float,
    x0,
    *,
    n: int = 1,
    ds: float | None = None,
    ds_min: float | None = None,
    ds_max: float | None = None,
    max_points: int = 400,
    locate_tol: float = 1e-7,
) -> Branch:
    """Follow the period-n orbit from ``x0`` near ``parameter = start`` toward ``stop``.

    The first orbit is found by shooting; the branch ends at ``stop``, at the edge of the
    parameter's valid range (``_bounds.py``: a predictor that would cross it is shortened
    to land on it), after ``max_points`` points, or when the step falls below ``ds_min``;
    :attr:`Branch.status` and :attr:`Branch.message` say which.  The arclength step
    ``ds`` grows by 1.5 after a correction of at most two Newton steps, else shrinks by
    1.5; bifurcations are located to ``locate_tol`` in arclength (``engine.py``).  Steps
    are in the units of (x0, parameter), the parameter counted in units of its range
    ``k = max(1, |stop - start|)`` (``engine.Settings.scale``); the defaults ``ds``,
    ``ds_min``, ``ds_max`` are ``0.02 k``, ``1e-5 k`` and ``0.1 k``.
    """
    started = time.perf_counter()
    k = max(1.0, abs(stop - start))
    ds = 0.02 * k if ds is None else ds
    ds_min = 1e-5 * k if ds_min is None else ds_min
    ds_max = 0.1 * k if ds_max is None else ds_max
    if not (ds > 0 and ds_min > 0 and ds_max >= ds_min):
        raise ValueError(
            f"steps must be positive (ds = {ds}, ds_min = {ds_min}, ds_max = {ds_max})"
        )
    if n < 1:
        raise ValueError(f"the period multiple n must be >= 1, got {n}")
    prob = ShootingProblem(system, parameter, n)
    if start not in prob.valid:
        raise ValueError(f"{parameter} = {start:g}: outside its valid range {prob.valid.rule()}")
    first = shoot(prob.system(start), x0, n, flow=prob.map.flow)
    # a range longer than 1 is the parameter's unit in the arclength (engine.Settings)
    settings = Settings(
        ds=ds / k,
        ds_min=ds_min / k,
        ds_max=ds_max / k,
        max_points=max_points,
        locate_tol=locate_tol,
        scale=k,
    )
    branch = continue_branch(prob, np.concatenate([first.x0, [start]]), stop, settings)
    return replace(branch, wall_time=time.perf_counter() - started)
