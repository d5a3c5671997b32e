"""The one pseudo-arclength continuation engine, for every problem that states its residual,
its Jacobian and its stability (BifurcationKit.jl's split: the problem says what, the
engine says how).

Unknowns ``z = (u, lambda)``.  Each step predicts along the unit tangent t of the branch
(the null vector of ``[G_u, G_lambda]``, oriented by the previous tangent) and corrects
with the Newton of ``newton.py`` (undamped) on

    ``G(u, lambda) = 0``,   ``t . (z - z_pred) = 0``

(Keller 1977, "Numerical solution of bifurcation and nonlinear eigenvalue problems"), so
the branch is followed round folds.  The step grows after easy corrections and shrinks
after hard or failed ones (:class:`Settings`, the step control as data).  Between two
accepted points the bifurcations are located on the arclength (Illinois false position):

* a **fold** where the tangent's parameter component changes sign;
* a **period doubling** or **Neimark-Sacker** point (and a multiplier through +1 where
  the branch does not turn: a branch point, recorded as a fold and named a branch point
  by ``Branch.named`` in what is printed and drawn) where a test function of
  ``floquet.py`` changes sign: ``det(M - I)``, ``det(M + I)``, the product of
  ``|mu|^2 - 1`` over the complex pairs (whose number must not change).

The branch ends at the end asked for or at the edge of the parameter's valid range
(``_bounds.py``; a predictor that would cross it is shortened to land on it, and the last
point is solved at the end exactly by the problem's :meth:`solve_at`), after
``max_points`` points, or when the step falls below its minimum.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Protocol

import numpy as np

from ._bounds import Interval
from .floquet import KINDS, Floquet
from .newton import newton
from .records import CRITICAL, Bifurcation, Branch, BranchPoint

__all__ = [
    "FAILURES",
    "ContinuationProblem",
    "Linearisation",
    "Settings",
    "continue_branch",
    "correct",
    "ending",
    "tangent",
]

# What a failed correction raises: NewtonError, ShootingError, a failed integration
# (RuntimeError), a singular system, or a value the model refuses (ValueError).
FAILURES = (RuntimeError, ValueError, np.linalg.LinAlgError)


@dataclass(frozen=True)
class Linearisation:
    """``G`` (m,) at one ``z`` with ``G_u`` (m, m) and ``G_lambda`` (m,); ``extra`` what
    the problem keeps for its stability (shooting: the monodromy and its trace integral)."""

    G: np.ndarray
    Gu: np.ndarray
    Glam: np.ndarray
    extra: object = None


class ContinuationProblem(Protocol):
    """What the engine needs of a problem (``continuation.py``: shooting;
    ``hb_continuation.py``: harmonic balance)."""

    parameter: str
    n: int
    valid: Interval

    def linearise(self, z, column=None) -> Linearisation:
        """G and its Jacobian at ``z``; ``column`` a ``G_lambda`` to use instead."""

    def frozen_column(self, z) -> np.ndarray | None:
        """The ``G_lambda`` the corrector keeps from the prediction ``z``, or None (it is
        evaluated at every iterate)."""

    def stability(self, z, lin: Linearisation) -> Floquet | None:
        """Floquet multipliers and verdict at ``z`` (None: the branch runs without)."""

    def tests(self, z, lin: Linearisation, floquet: Floquet | None = None):
        """The test functions (fold, period doubling, Neimark-Sacker, number of complex
        pairs) at ``z``, or None."""

    def multipliers(self, z, lin: Linearisation) -> np.ndarray | None:
        """The Floquet multipliers at ``z`` (for the critical one of a bifurcation)."""

    def point(self, z, sign: int, floquet: Floquet | None) -> BranchPoint:
        """The branch record of ``z``."""

    def state(self, z) -> np.ndarray:
        """The orbit's state at tau = 0 (mod nT) at ``z``, (n_states,)."""

    def solve_at(self, lam: float, guess, sign: int) -> BranchPoint:
        """The solution at ``lam`` exactly from ``guess`` (u only); raises on failure."""

    def evidence(self, z) -> dict:
        """What else shows a bifurcation located at ``z`` (may be empty)."""

    def branch_fields(self) -> dict:
        """What the :class:`Branch` keeps of the problem (state names, model, ...)."""


@dataclass(frozen=True)
class Settings:
    """The engine's step control and tolerances.

    ``ds``: the first arclength step; ``ds_min``, ``ds_max`` its floor and ceiling;
    ``dlam_max``: the most the parameter may move in one step (None: no cap).  After a
    correction of at most ``easy`` Newton steps the step is multiplied by ``grow``, after
    more than ``hard`` divided by ``shrink``; a failed one halves it.  ``tol`` and
    ``max_iter``: the corrector's (max-norm of the residual, Newton steps);
    ``locate_tol``: the located bracket in arclength, ``locate_iter`` its corrector's
    Newton steps.
    """

    ds: float
    ds_min: float
    ds_max: float
    dlam_max: float | None = None
    max_points: int = 400
    tol: float = 1e-10
    max_iter: int = 8
    easy: int = 2
    hard: int = 2
    grow: float = 1.5
    shrink: float = 1.5
    locate_tol: float = 1e-7
    locate_iter: int = 12
    # the parameter's unit in the arclength: lambda counts as lambda / scale beside the
    # unknowns, and ds, ds_min, ds_max, locate_tol are in those units (the front doors
    # take the range when it exceeds 1: a speed in rpm or a torque in N m then moves the
    # unknowns as much per step as omega does; at 1, the arclength of (u, lambda))
    scale: float = 1.0

    def next_step(self, ds: float, steps: int, t_lam: float) -> float:
        """The step after a correction of ``steps`` Newton steps."""
        if steps <= self.easy:
            ds = min(ds * self.grow, self.ds_max)
        elif steps > self.hard:
            ds = max(ds / self.shrink, self.ds_min)
        if self.dlam_max is not None and abs(t_lam) > 0:
            ds = min(ds, self.dlam_max / abs(t_lam))
        return ds


def tangent(Gu, Glam, previous=None, scale: float = 1.0) -> np.ndarray:
    """The unit tangent ``t`` (m + 1,) of the branch: the null vector of ``[G_u, G_lambda]``
    (by SVD), or, given the previous tangent, the solution of the bordered system
    ``[G_u G_lambda; previous] t = (0, 1)`` (so it keeps the orientation); unit in the
    norm that counts lambda as lambda / ``scale`` (:class:`Settings`)."""
    A = np.hstack([Gu, Glam[:, None]])
    if previous is None:
        t = np.linalg.svd(A)[2][-1]
    else:  # (the orientation in the scaled inner product, as the step's hyperplane)
        row = previous if scale == 1.0 else np.r_[previous[:-1], previous[-1] / scale**2]
        t = np.linalg.solve(
            np.vstack([A, row[None, :]]), np.concatenate([np.zeros(A.shape[0]), [1.0]])
        )
    if scale == 1.0:
        return t / np.linalg.norm(t)
    return t / np.sqrt(t[:-1] @ t[:-1] + (t[-1] / scale) ** 2)


def correct(problem: ContinuationProblem, z_pred, t, tol: float, max_iter: int, scale: float = 1.0):
    """Newton on ``(G(z), t . W (z - z_pred))`` from the prediction (``W`` weighs lambda
    by ``1 / scale**2``: the step's hyperplane in the scaled arclength); returns the point,
    the Newton steps taken and the linearisation there.  Raises one of :data:`FAILURES`."""
    column = problem.frozen_column(z_pred)
    row = t if scale == 1.0 else np.r_[t[:-1], t[-1] / scale**2]

    def fun(z):
        lin = problem.linearise(z, column)
        H = np.concatenate([lin.G, [row @ (z - z_pred)]])
        A = np.vstack([np.hstack([lin.Gu, lin.Glam[:, None]]), row[None, :]])
        return H, A, lin

    found = newton(fun, z_pred, tol=tol, max_iter=max_iter, damped=False, min_steps=1)
    return found.z, found.steps, found.extra


def _sign(t) -> int:
    return int(np.sign(t[-1])) or 1


def continue_branch(
    problem: ContinuationProblem, z, stop: float, settings: Settings, *, locate: bool = True
) -> Branch:
    """Continue the branch through ``z = (u, lambda)`` (a solution) toward ``stop``.

    Returns the :class:`~.records.Branch` with the bifurcations located (``locate``)."""
    start = float(z[-1])
    lin = problem.linearise(z)
    t = tangent(lin.Gu, lin.Glam, scale=settings.scale)
    if np.sign(t[-1]) != (np.sign(stop - start) or 1.0):
        t = -t
    fl = problem.stability(z, lin)
    points = [problem.point(z, _sign(t), fl)]
    tests = problem.tests(z, lin, fl)
    found: list[Bifurcation] = []
    notes: list[str] = []
    valid, s = problem.valid, settings
    lo, hi = valid.ends(start, stop)
    status, message = "max-points", f"stopped after {s.max_points} points"
    ds = s.ds

    def land(end, guess, sign):
        """Solve at ``end`` exactly from ``guess`` and end the branch there."""
        try:
            points.append(problem.solve_at(end, guess, sign))
        except FAILURES:
            pass
        result = ending(problem.parameter, valid, start, stop, lo, hi, end)
        if result[0] == "turned":
            notes.append(
                f"the branch turned back and left the range at {problem.parameter} = "
                f"{end:g}; continue from there to follow it further"
            )
        return result

    while len(points) < s.max_points:
        end = None
        if z[-1] + ds * t[-1] not in valid:
            # the predictor would cross the valid range's edge: land on the range's end
            end = hi if t[-1] > 0 else lo
            if abs(end - z[-1]) <= 1e-12 * max(1.0, abs(end)):
                status, message = ending(problem.parameter, valid, start, stop, lo, hi, end)
                break
            ds = (end - z[-1]) / t[-1]
        try:
            z_new, steps, lin_new = correct(problem, z + ds * t, t, s.tol, s.max_iter, s.scale)
        except FAILURES as err:
            if end is not None:
                status, message = land(end, z[:-1] + ds * t[:-1], _sign(t))
                break
            ds /= 2
            if ds < s.ds_min:
                status = "stalled"
                # a failed integration says why (a grazing mesh's step budget, for one)
                why = str(err).splitlines()[0] if isinstance(err, RuntimeError) else ""
                message = (
                    f"the corrector failed with the smallest step ({s.ds_min:g}) at "
                    f"{problem.parameter} = {z[-1]:.6g}" + (f" ({why})" if why else "")
                )
                notes.append(message)
                break
            continue
        t_new = tangent(lin_new.Gu, lin_new.Glam, t, s.scale)
        fl_new = problem.stability(z_new, lin_new)
        tests_new = problem.tests(z_new, lin_new, fl_new)
        if locate:
            step = (z, t, ds, tests, t_new, tests_new)
            found += _events(problem, step, s, len(points))
        if end is not None or not lo - 1e-12 <= z_new[-1] <= hi + 1e-12:
            # Land on the end of the range: solve at the end value from the state
            # interpolated between the last two points (the point past it is not kept).
            end = end if end is not None else hi if z_new[-1] > hi else lo
            w = (end - z[-1]) / (z_new[-1] - z[-1]) if z_new[-1] != z[-1] else 1.0
            status, message = land(end, z[:-1] + w * (z_new[:-1] - z[:-1]), _sign(t_new))
            break
        z, t, tests = z_new, t_new, tests_new
        points.append(problem.point(z, _sign(t), fl_new))
        ds = s.next_step(ds, steps, t[-1])
    return Branch(
        problem.parameter,
        problem.n,
        tuple(points),
        tuple(found),
        status,
        message,
        tuple(notes),
        **problem.branch_fields(),
    )


def _events(problem, step, s: Settings, index: int) -> list[Bifurcation]:
    """The bifurcations between ``z`` and the next point: a fold where the tangent's
    parameter component changes sign, and the sign changes of the test functions."""
    z, t, ds, tests, t_new, tests_new = step
    out = []
    folded = np.sign(t_new[-1]) != np.sign(t[-1])
    if folded:
        # the tangent alone decides a fold: no stability in the location
        b = _locate(problem, z, t, ds, "fold", None, (t[-1], t_new[-1]), s, index)
        out.append(replace(b, turns=True))
    if tests is None or tests_new is None:
        return out
    for k, kind in enumerate(KINDS):
        if np.sign(tests_new[k]) == np.sign(tests[k]) or tests[k] == 0:
            continue
        if kind == "fold" and folded:
            continue  # the fold located on the tangent
        if kind == "neimark-sacker" and tests_new[3] != tests[3]:
            continue  # complex pairs merged or split on the real axis: no crossing
        b = _locate(problem, z, t, ds, kind, k, (tests[k], tests_new[k]), s, index)
        if kind == "fold":  # a multiplier through +1 where the branch does not turn
            b = replace(b, turns=False)
        if kind != "neimark-sacker" or abs(abs(b.multiplier) - 1.0) < 1e-3:
            out.append(b)
    return out


def _locate(problem, z0, t0, ds, kind, k, ends, s: Settings, index) -> Bifurcation:
    """The arclength between ``z0`` and ``z0 + ds t0`` where a test changes sign: the
    tangent's parameter component (``k`` None) or test function ``k``, whose values at
    the two ends are ``ends``.  The Illinois variant of false position (Dowell and
    Jarratt 1971, "A modified regula falsi method for computing the root of an
    equation"): the tests are smooth along the step, so a few corrections do what some
    thirty bisections did; it stops when the bracket is below ``s.locate_tol`` (relative
    to the step when that is longer than 1) or the test is below 1e-12."""
    a, b = 0.0, ds
    f_a, f_b = float(ends[0]), float(ends[1])
    z_mid, lin, side, failed = z0, None, 0, None
    for _ in range(40):
        mid = b - f_b * (b - a) / (f_b - f_a) if f_b != f_a else 0.5 * (a + b)
        if not min(a, b) < mid < max(a, b):
            mid = 0.5 * (a + b)
        try:
            z_try, _, lin_try = correct(problem, z0 + mid * t0, t0, s.tol, s.locate_iter, s.scale)
        except FAILURES as err:  # keep the bracket reached so far, and say so
            why = str(err).splitlines()[0] if str(err) else type(err).__name__
            failed = (
                f"not located: the corrector failed inside the bracket [{a:.3g}, {b:.3g}] "
                f"of arclength ({why}); the point is its last solved end"
            )
            break
        z_mid, lin = z_try, lin_try
        if k is None:
            f = tangent(lin.Gu, lin.Glam, t0, s.scale)[-1]
        else:
            f = problem.tests(z_mid, lin)[k]
        if np.sign(f) == np.sign(f_a):
            a, f_a = mid, f
            if side == -1:
                f_b /= 2
            side = -1
        else:
            b, f_b = mid, f
            if side == 1:
                f_a /= 2
            side = 1
        if abs(b - a) < s.locate_tol * max(1.0, abs(ds)) or abs(f) < 1e-12:
            break
    if lin is None:
        lin = problem.linearise(z0)
    mu = problem.multipliers(z_mid, lin)
    crit = None
    if mu is not None:
        target = CRITICAL.get(kind)
        if target is None:
            crit = complex(mu[np.argmin(np.abs(np.abs(mu) - 1.0))])
        else:
            crit = complex(mu[np.argmin(np.abs(mu - target))])
    evidence = problem.evidence(z_mid)
    if failed:
        evidence = {**evidence, "location": failed}
    return Bifurcation(
        kind,
        float(z_mid[-1]),
        problem.state(z_mid),
        crit,
        problem.parameter,
        index,
        evidence,
    )


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
