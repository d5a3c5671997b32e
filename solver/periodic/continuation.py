"""Pseudo-arclength continuation of periodic orbits, with bifurcation detection.

Unknowns z = (x0, lambda): the orbit's state at tau = 0 (mod nT) and the parameter.
Each step predicts along the tangent t of the branch and corrects with Newton on

    ``G(x0, lambda) = phi_{nT}(x0; lambda) - x0 = 0``,   ``t . (z - z_pred) = 0``

(Keller's pseudo-arclength condition), so the branch is followed round folds.  G is the
stroboscopic map of ``flow.py`` minus the identity, with one flow map for the whole
branch (lambda changes only the parameter vector passed to it); dG/dx0 is the monodromy
minus I, dG/dlambda a central difference.  The corrector is the Newton of ``newton.py``
(undamped).  The step adapts to Newton's effort.  Between two accepted points, sign
changes of the test functions of ``floquet.py`` (fold, period doubling, Neimark-Sacker)
are located by bisection on the arclength.  At a period doubling the branch can be
switched onto the period-2n orbit (``switching.py``).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..integrate._quiet import quiet
from ..system import System
from ._bounds import Interval, interval_of
from .floquet import KINDS, Floquet, bifurcation_tests, floquet
from .flow import StroboscopicMap
from .newton import newton
from .shooting import ShootingError, shoot

__all__ = ["Bifurcation", "Branch", "continue_orbit"]


@dataclass(frozen=True)
class Bifurcation:
    kind: str  # "fold", "period-doubling", "neimark-sacker"
    value: float
    x0: np.ndarray
    multiplier: complex

    def describe(self) -> dict:
        return {
            "type": self.kind,
            "value": self.value,
            "multiplier": {"re": float(self.multiplier.real), "im": float(self.multiplier.imag)},
            "x0": [float(v) for v in self.x0],
        }

    to_dict = describe


@dataclass
class Branch:
    """A continued branch of period-n orbits: per point the parameter value, the orbit's
    state at tau = 0 (mod nT), its stability and multipliers; the bifurcations located."""

    parameter: str
    n: int
    values: list = field(default_factory=list)
    states: list = field(default_factory=list)
    stable: list = field(default_factory=list)
    multipliers: list = field(default_factory=list)
    bifurcations: list = field(default_factory=list)
    message: str = ""
    # "complete" (reached the end asked for), "boundary" (stopped at the edge of the
    # parameter's valid range), "turned" (a fold took it out at the start's side),
    # "stalled" (the step fell below its minimum), "max-points"
    status: str = "complete"
    state_names: tuple = ()
    model: dict = field(default_factory=dict)  # name, hash, base values and scales

    def describe(self) -> dict:
        return {
            "parameter": self.parameter,
            "period_multiple": self.n,
            "values": [float(v) for v in self.values],
            "x0": [[float(v) for v in s] for s in self.states],
            "stable": [bool(s) for s in self.stable],
            "max_multiplier": [float(np.max(np.abs(m))) for m in self.multipliers],
            "bifurcations": [b.describe() for b in self.bifurcations],
            "status": self.status,
            "message": self.message,
        }

    def to_dict(self) -> dict:
        """:meth:`describe` with the state names, the model (name, hash, base values) and
        the scales back to SI."""
        return self.model | {"states": list(self.state_names)} | self.describe()

    def to_table(self) -> tuple[list, list]:
        """One row per branch point: the parameter, stability, largest |multiplier|, x0."""
        n = len(self.states[0]) if self.states else 0
        names = self.state_names or tuple(f"x0_{i}" for i in range(n))
        columns = [self.parameter, "stable", "max_multiplier", *names]
        rows = [
            [float(v), bool(s), float(np.max(np.abs(m))), *map(float, x)]
            for v, s, m, x in zip(
                self.values, self.stable, self.multipliers, self.states, strict=True
            )
        ]
        return columns, rows

    def save(self, path):
        """Write to ``path``: ``.json``, ``.csv`` or ``.mat`` (see ``solver/export.py``)."""
        from ..export import save

        return save(self, path)


class _Problem:
    """G, its Jacobian and the test functions at (x0, lambda) for one branch, on one
    stroboscopic map whose parameter vector follows lambda."""

    def __init__(self, system: System, parameter: str, n: int):
        self.base, self.parameter, self.n = system, parameter, n
        self.valid = interval_of(system, parameter)
        self.map = StroboscopicMap(system, n)

    def system(self, lam: float) -> System:
        if lam not in self.valid:
            raise ValueError(f"{self.parameter} = {lam:g} is outside {self.valid.rule()}")
        return self.base.with_values(**{self.parameter: float(lam)})

    def p(self, lam) -> np.ndarray:
        return self.system(lam).p

    def G(self, x, lam) -> np.ndarray:
        with quiet():  # CasADi's dump of a failed integration: the error says it
            return self.map(x, self.p(lam)) - x

    def jacobian(self, x, lam):
        with quiet():
            xe, M, q = self.map.jacobian(x, self.p(lam))
        h = 1e-6 * max(1.0, abs(lam))
        # one-sided at an end of the valid range (damping_ratio = 0)
        up, dn = lam + h, lam - h
        if up not in self.valid:
            up = lam
        elif dn not in self.valid:
            dn = lam
        dG = (self.G(x, up) - self.G(x, dn)) / (up - dn)
        return xe - x, M, dG, q


def _tangent(Gx, Gl, previous=None) -> np.ndarray:
    A = np.hstack([Gx, Gl[:, None]])
    if previous is None:
        t = np.linalg.svd(A)[2][-1]
    else:
        t = np.linalg.solve(
            np.vstack([A, previous[None, :]]), np.concatenate([np.zeros(A.shape[0]), [1.0]])
        )
    return t / np.linalg.norm(t)


def _correct(prob: _Problem, z_pred, t, tol=1e-10, max_iter=8):
    """Newton on (G, t . (z - z_pred)) from the prediction; returns the point, Newton's
    evaluations, and the monodromy, trace integral and dG/dlambda there."""
    N = z_pred.size - 1

    def fun(z):
        G, M, dG, q = prob.jacobian(z[:-1], z[-1])
        H = np.concatenate([G, [t @ (z - z_pred)]])
        A = np.vstack([np.hstack([M - np.eye(N), dG[:, None]]), t[None, :]])
        return H, A, (M, q, dG)

    found = newton(fun, z_pred, tol=tol, max_iter=max_iter, damped=False, min_steps=1)
    M, q, dG = found.extra
    return found.z, found.steps + 1, M, q, dG


def continue_orbit(
    system: System,
    parameter: str,
    start: float,
    stop: float,
    x0,
    *,
    n: int = 1,
    ds: float = 0.02,
    ds_min: float = 1e-5,
    ds_max: float = 0.1,
    max_points: int = 400,
    locate_tol: float = 1e-7,
) -> Branch:
    """Follow the period-n orbit from ``x0`` near ``parameter = start`` toward ``stop``.

    The first orbit is found by shooting; the branch ends at ``stop``, at the edge of the
    parameter's valid range (``_bounds.py``: a predictor that would cross it is shortened
    to land on it), after ``max_points`` points, or when the step falls below ``ds_min``;
    :attr:`Branch.status` and :attr:`Branch.message` say which.
    """
    if not (ds > 0 and ds_min > 0 and ds_max >= ds_min):
        raise ValueError(
            f"steps must be positive (ds = {ds}, ds_min = {ds_min}, ds_max = {ds_max})"
        )
    if n < 1:
        raise ValueError(f"the period multiple n must be >= 1, got {n}")
    prob = _Problem(system, parameter, n)
    if start not in prob.valid:
        raise ValueError(f"{parameter} = {start:g}: outside its valid range {prob.valid.rule()}")
    first = shoot(prob.system(start), x0, n, flow=prob.map.flow)
    z = np.concatenate([first.x0, [start]])
    G, M, dG, q = prob.jacobian(z[:-1], z[-1])
    t = _tangent(M - np.eye(M.shape[0]), dG)
    direction = np.sign(stop - start) or 1.0
    if np.sign(t[-1]) != direction:
        t = -t
    model = {
        "model": system.name,
        "model_hash": system.model_hash,
        "base_values": {k: float(v) for k, v in system.values.items()},
        "scales": system.scales(),
    }
    branch = Branch(parameter, n, state_names=system.states, model=model)
    fl = floquet(M, q)

    def record(z, fl: Floquet):
        branch.values.append(float(z[-1]))
        branch.states.append(z[:-1].copy())
        branch.stable.append(fl.stable)
        branch.multipliers.append(fl.multipliers)

    def land(end, guess):
        """Shoot at ``end`` exactly from ``guess`` and end the branch there."""
        try:
            last = shoot(prob.system(end), guess, n, flow=prob.map.flow)
            record(np.concatenate([last.x0, [end]]), last.floquet)
        except (ShootingError, ValueError, RuntimeError, np.linalg.LinAlgError):
            pass
        branch.status, branch.message = ending(parameter, prob.valid, start, stop, lo, hi, end)

    record(z, fl)
    tests = bifurcation_tests(M)
    lo, hi = prob.valid.ends(start, stop)
    while len(branch.values) < max_points:
        end = None
        if z[-1] + ds * t[-1] not in prob.valid:
            # the predictor would cross the valid range's edge: land on the range's end
            end = hi if t[-1] > 0 else lo
            if abs(end - z[-1]) <= 1e-12 * max(1.0, abs(end)):
                branch.status, branch.message = ending(
                    parameter, prob.valid, start, stop, lo, hi, end
                )
                break
            ds = (end - z[-1]) / t[-1]
        try:
            z_new, iters, M_new, q_new, dG_new = _correct(prob, z + ds * t, t)
        except (ShootingError, np.linalg.LinAlgError, RuntimeError, ValueError):
            # ValueError: the corrector reached values the model refuses
            if end is not None:
                land(end, z[:-1] + ds * t[:-1])
                break
            ds /= 2
            if ds < ds_min:
                branch.status = "stalled"
                branch.message = f"step fell below {ds_min:g} at {parameter} = {z[-1]:.6g}"
                break
            continue
        t_new = _tangent(M_new - np.eye(M_new.shape[0]), dG_new, t)
        tests_new = bifurcation_tests(M_new)
        for k, kind in enumerate(KINDS):
            if np.sign(tests_new[k]) == np.sign(tests[k]) or tests[k] == 0:
                continue
            if kind == "neimark-sacker" and tests_new[3] != tests[3]:
                continue  # complex pairs merged or split on the real axis: no crossing
            found = _locate(prob, z, t, ds, k, kind, tests[k], locate_tol)
            if kind != "neimark-sacker" or abs(abs(found.multiplier) - 1.0) < 1e-3:
                branch.bifurcations.append(found)
        if end is not None or not lo - 1e-12 <= z_new[-1] <= hi + 1e-12:
            # Land on the end of the range: shoot at the end value from the state
            # interpolated between the last two points (the point past it is not kept).
            end = end if end is not None else hi if z_new[-1] > hi else lo
            w = (end - z[-1]) / (z_new[-1] - z[-1]) if z_new[-1] != z[-1] else 1.0
            land(end, z[:-1] + w * (z_new[:-1] - z[:-1]))
            break
        z, t, tests = z_new, t_new, tests_new
        record(z, floquet(M_new, q_new))
        ds = min(ds * 1.5, ds_max) if iters <= 3 else max(ds / 1.5, ds_min)
    else:
        branch.status, branch.message = "max-points", f"stopped after {max_points} points"
    return branch


def ending(parameter: str, valid: Interval, start, stop, lo, hi, end) -> tuple[str, str]:
    """(status, message) of a branch that ended at ``end`` of ``[lo, hi]``: the end asked
    for ("complete"), an edge of the valid range ("boundary": short of the end asked
    for, or that end itself), or the start's side after a fold ("turned")."""
    toward = hi if stop > start else lo
    if end == toward == stop and not valid.is_end(end):
        return "complete", f"reached the end of [{lo:g}, {hi:g}] at {parameter} = {end:g}"
    if end == toward == stop:
        return "boundary", (
            f"stopped at {parameter} = {end:g}, the end asked for and the boundary of the "
            f"valid range {valid.rule()}"
        )
    if end == toward:
        return "boundary", (
            f"stopped at the boundary of the valid range {valid.rule()} at {parameter} = "
            f"{end:.6g}, short of {stop:g}; the branch up to there is kept"
        )
    return "turned", (
        f"reached the end of [{lo:g}, {hi:g}] at {parameter} = {end:g} (the side it "
        "started from: the branch turned at a fold)"
    )


def _locate(prob, z0, t0, ds, k, kind, f0, tol) -> Bifurcation:
    """Bisection on the arclength between z0 (test value f0) and z0 + ds t0."""
    a, b = 0.0, ds
    z_mid = z0
    M = prob.jacobian(z0[:-1], z0[-1])[1]
    for _ in range(40):
        mid = (a + b) / 2
        try:
            z_try, _, M_try, _, _ = _correct(prob, z0 + mid * t0, t0, max_iter=12)
        except (ShootingError, np.linalg.LinAlgError, RuntimeError, ValueError):
            break  # keep the bracket reached so far
        z_mid, M = z_try, M_try
        f = bifurcation_tests(M)[k]
        if np.sign(f) == np.sign(f0):
            a = mid
        else:
            b = mid
        if b - a < tol:
            break
    mu = np.linalg.eigvals(M)
    target = {"fold": 1.0, "period-doubling": -1.0}.get(kind)
    if target is None:
        crit = mu[np.argmin(np.abs(np.abs(mu) - 1.0))]
    else:
        crit = mu[np.argmin(np.abs(mu - target))]
    return Bifurcation(kind, float(z_mid[-1]), z_mid[:-1].copy(), complex(crit))
