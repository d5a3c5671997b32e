"""Continuation of harmonic-balance solutions in any parameter: the problem on the Fourier
coefficients, and its front door :func:`continue_hb` on the engine of ``engine.py``.

Unknowns ``z = (X, lambda)``: the coefficients (states x (2H + 1), flattened state-major)
and the parameter; ``G(X, lambda) = R(X, lambda)``, the residual of the alternating
frequency-time method (``harmonic_balance.py``) with its Jacobian in X from the generated
one.  ``G_lambda`` is a central difference (step ``1e-7 max(1, |lambda|)``, one-sided at
an end of the valid range) that the corrector takes once at the prediction: its error,
about 1e-14, only perturbs the Newton direction.  Stability: Hill's multipliers
(``hill.py``), with the test functions of ``floquet.py`` taken from them.
"""

from __future__ import annotations

import time
from dataclasses import replace

import numpy as np

from ..system import System
from ._bounds import interval_of
from .continuation import model_fields
from .engine import Linearisation, Settings, continue_branch
from .floquet import Floquet, multiplier_tests
from .flow import FlowMap, StroboscopicMap
from .harmonic_balance import HarmonicBalance, harmonic_balance, hill
from .hb_confirm import RTOL, located_monodromy, screen
from .newton import newton
from .records import Branch, BranchPoint

__all__ = ["HarmonicBalanceProblem", "continue_hb", "monodromy_check"]


class HarmonicBalanceProblem:
    """``R(X, lambda)``, its Jacobian and Hill's stability for one parameter."""

    def __init__(
        self,
        system: System,
        parameter: str,
        problem: HarmonicBalance,
        *,
        tol: float = 1e-10,
        stability: bool = True,
        check: bool = True,
    ):
        self.system, self.parameter, self.problem = system, parameter, problem
        self.n = problem.n
        self.shape = (system.n, problem.M)
        self.valid = interval_of(system, parameter)  # a scene or model parameter
        self.tol, self.with_stability, self.check = tol, stability, check
        # the located monodromies at the events of a piecewise model, by parameter value
        # (``hb_confirm.py`` reuses them)
        self.monodromies: dict[float, np.ndarray] = {}

    def p(self, lam: float) -> np.ndarray:
        if lam not in self.valid:
            raise ValueError(f"{self.parameter} = {lam:g} is outside {self.valid.rule()}")
        return self.system.parameters_with(**{self.parameter: lam})

    def frozen_column(self, z) -> np.ndarray:
        """dR/d(lambda) at ``z`` by a central difference (one-sided at an end of the valid
        range), (states (2H + 1),)."""
        X, lam = z[:-1].reshape(self.shape), float(z[-1])
        h = 1e-7 * max(1.0, abs(lam))
        a, b = lam + h, lam - h
        if a not in self.valid:
            a = lam
        elif b not in self.valid:
            b = lam
        up = self.problem.residual(X, self.p(a), jacobian=False)[0]
        dn = self.problem.residual(X, self.p(b), jacobian=False)[0]
        return ((up - dn) / (a - b)).ravel()

    def linearise(self, z, column=None) -> Linearisation:
        X, lam = z[:-1].reshape(self.shape), float(z[-1])
        R, Jx = self.problem.residual(X, self.p(lam))
        Jl = self.frozen_column(z) if column is None else column
        return Linearisation(R.ravel(), Jx, Jl)

    def _hill(self, z) -> Floquet:
        return hill(self.problem, z[:-1].reshape(self.shape), self.p(float(z[-1])))[1]

    def stability(self, z, lin: Linearisation) -> Floquet | None:
        return self._hill(z) if self.with_stability else None

    def tests(self, z, lin: Linearisation, floquet: Floquet | None = None):
        if not self.with_stability:
            return None
        return multiplier_tests((floquet or self._hill(z)).multipliers)

    def multipliers(self, z, lin: Linearisation) -> np.ndarray | None:
        return self._hill(z).multipliers if self.with_stability else None

    def state(self, z) -> np.ndarray:
        X = z[:-1].reshape(self.shape)
        return self.problem.time_series(X, np.zeros(1))[:, 0]

    def point(self, z, sign: int, fl: Floquet | None) -> BranchPoint:
        X, lam = z[:-1].reshape(self.shape), float(z[-1])
        if fl is None:
            return BranchPoint(lam, self.state(z), None, None, None, sign, X)
        return BranchPoint(lam, self.state(z), fl.multipliers, fl.stable, fl.stability, sign, X)

    def solve_at(self, lam: float, guess, sign: int) -> BranchPoint:
        """Newton in X at ``lam`` exactly, from ``guess``."""
        p = self.p(lam)

        def fun(x):
            R, J = self.problem.residual(x.reshape(self.shape), p)
            return R.ravel(), J, None

        found = newton(fun, guess, tol=self.tol, max_iter=19, damped=False)
        z = np.r_[found.z, lam]
        return self.point(z, sign, self.stability(z, None))

    def evidence(self, z) -> dict:
        return monodromy_check(self, z, self.n) if self.check else {}

    def branch_fields(self) -> dict:
        return model_fields(self.system) | {"harmonic_balance": self.problem}


def monodromy_check(curve: HarmonicBalanceProblem, z, n: int) -> dict:
    """Hill's multipliers at ``z`` against the monodromy of the time integration from the
    harmonic-balance state: the largest distance from a Hill multiplier to the nearest
    monodromy multiplier, and the largest monodromy multiplier's modulus.  A smooth model:
    central differences of the flow over n T, compiled DOP853 at rtol 1e-12, the
    2 n_states runs in one lockstep group.  A piecewise model: the located variational
    equations (:func:`~.hb_confirm.located_monodromy`, kept in ``curve.monodromies``)."""
    X, lam = z[:-1].reshape(curve.shape), float(z[-1])
    p = curve.p(lam)
    x0 = curve.problem.synthesis(X)[:, 0]
    if curve.system.piecewise:
        M = _located(curve, lam, x0)
    else:
        M = _central(curve, p, x0, n)
    mu = np.linalg.eigvals(M)
    _, fl = hill(curve.problem, X, p)
    gap = max(float(np.min(np.abs(mu - m))) for m in fl.multipliers)
    return {"hill_vs_monodromy": gap, "max_monodromy_multiplier": float(np.max(np.abs(mu)))}


def _located(curve: HarmonicBalanceProblem, lam: float, x0) -> np.ndarray:
    flow = FlowMap(curve.system, rtol=RTOL, atol=RTOL * 1e-2, locate=True)
    smap = StroboscopicMap(curve.system, curve.n, flow=flow)
    M = located_monodromy(smap, curve.system, curve.parameter, lam, x0)
    curve.monodromies[lam] = M
    return M


def _central(curve: HarmonicBalanceProblem, p, x0, n: int) -> np.ndarray:
    from ..integrate.native import run_batch

    nx = x0.size
    h = 1e-6 * max(1.0, float(np.max(np.abs(x0))))
    starts = np.vstack([x0 + h * e for e in np.eye(nx)] + [x0 - h * e for e in np.eye(nx)])
    P = np.repeat(p[None, :], 2 * nx, axis=0)
    run = run_batch(
        curve.system.module,
        P,
        starts,
        method="dop853",
        rtol=1e-12,
        atol=1e-14,
        transient=0,
        periods=n,
        samples_per_period=1,
    )
    end = run.x[:, -1, :]
    return ((end[:nx] - end[nx:]) / (2 * h)).T


def continue_hb(
    system: System,
    parameter: str,
    start: float,
    stop: float,
    *,
    harmonics: int = 15,
    n: int = 1,
    samples: int | None = None,
    guess=None,
    ds: float | None = None,
    ds_max: float | None = None,
    dlam_max: float | None = None,
    max_points: int = 20_000,
    tol: float = 1e-10,
    stability: bool = True,
    locate: bool = True,
    check: bool = True,
    confirm: bool | None = None,
) -> Branch:
    """Continue the harmonic-balance solution from ``parameter = start`` to ``stop``.

    The first solution comes from :func:`harmonic_balance` (``guess`` as there).
    ``ds``: the first arclength step (default 1/200 of the range); ``ds_max`` its ceiling
    (default 1/20 of the range); ``dlam_max`` caps the parameter's change per step (the
    step is then at most ``dlam_max / |t_lambda|``: even resolution in the parameter
    where the curve runs straight, free steps where it turns).  The step grows by 1.5
    after a correction of at most three Newton steps and halves after more than six.
    Stops when the parameter leaves ``[start, stop]`` (the last point is solved at the
    end exactly), at the edge of its valid range (``_bounds.py``; a predictor that would
    cross it is shortened to land on it), or after ``max_points`` points; ``status`` and
    ``message`` say which.  ``stability``: Hill's multipliers at every point (and the
    period doublings and Neimark-Sacker points located); ``check``: every located
    bifurcation also carries the distance of Hill's multipliers from the monodromy of a
    time integration there (:func:`monodromy_check`) as its evidence.  ``confirm``
    (default: on a piecewise model, with ``stability`` and ``locate``): keep only the
    events the monodromy of a located time integration confirms, typed by it
    (:func:`~.hb_confirm.screen`; the branch's notes count the dropped ones).
    """
    started = time.perf_counter()
    if start == stop:
        raise ValueError(f"start and stop are both {start:g}: nothing to continue")
    valid = interval_of(system, parameter)
    if start not in valid:
        raise ValueError(f"{parameter} = {start:g}: outside its valid range {valid.rule()}")
    span = abs(stop - start)
    base = system.with_values(**{parameter: start})
    first = harmonic_balance(
        base, guess, harmonics=harmonics, n=n, samples=samples, tol=tol, stability=False
    )
    problem = HarmonicBalance(system, harmonics, n, first.samples)
    curve = HarmonicBalanceProblem(
        system, parameter, problem, tol=tol, stability=stability, check=check
    )
    scale = max(1.0, span)  # (engine.Settings.scale; the steps below in its units)
    settings = Settings(
        ds=(ds or span / 200) / scale,
        ds_min=span * 1e-9 / scale,
        ds_max=(ds_max or span / 20) / scale,
        dlam_max=dlam_max,
        max_points=max_points,
        tol=tol,
        max_iter=9,
        easy=3,
        hard=6,
        shrink=2.0,
        locate_tol=1e-10,
        locate_iter=9,
        scale=scale,
    )
    z = np.r_[first.coefficients.ravel(), float(start)]
    branch = continue_branch(curve, z, stop, settings, locate=locate)
    if confirm is None:
        confirm = system.piecewise and stability and locate
    if confirm:
        branch = screen(system, branch, curve.monodromies).branch
    return replace(branch, wall_time=time.perf_counter() - started)
