"""Pseudo-arclength continuation of harmonic-balance solutions in any parameter.

The unknowns are the Fourier coefficients and the parameter, ``z = (X, lambda)``; each
step predicts along the unit tangent of the solution curve and corrects with Newton on
``R(X, lambda) = 0`` plus the arclength condition ``t . (z - z_pred) = 0`` (Keller 1977,
"Numerical solution of bifurcation and nonlinear eigenvalue problems").  The Jacobian in
``X`` is the generated one through the AFT (``harmonic_balance.py``); the column in the
parameter is a central difference (its error, about 1e-14, only perturbs the predictor).
The step grows after easy corrections and shrinks after hard or failed ones.

Folds are where the tangent's parameter component changes sign; a change of Hill's
stability between two points is a fold, a period doubling (a multiplier through -1) or a
Neimark-Sacker point (a complex pair through the unit circle).  Each is located by
bisection along the arclength between the two points.
"""

from __future__ import annotations

import numpy as np

from ..system import System
from ._bounds import interval_of
from .continuation import _tangent as _null_tangent
from .continuation import ending
from .harmonic_balance import HarmonicBalance, harmonic_balance, hill
from .hb_branch import HBBranch, HBPoint

__all__ = ["HBBranch", "HBPoint", "continue_hb"]


class _Curve:
    """R(X, lambda) and its Jacobians for one parameter."""

    def __init__(self, system: System, parameter: str, problem: HarmonicBalance):
        self.system, self.parameter, self.problem = system, parameter, problem
        self.shape = (system.n, problem.M)
        self.size = system.n * problem.M
        self.valid = interval_of(system, parameter)  # a scene or model parameter

    def p(self, lam: float) -> np.ndarray:
        if lam not in self.valid:
            raise ValueError(f"{self.parameter} = {lam:g} is outside {self.valid.rule()}")
        return self.system.parameters_with(**{self.parameter: lam})

    def column(self, z) -> np.ndarray:
        """dR/d(lambda) by a central difference (one-sided at an end of the valid range)."""
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

    def __call__(self, z, column=None):
        """(R, [dR/dX, dR/dlambda]); ``column``: a dR/dlambda already at hand (the
        corrector keeps the predictor's: it only perturbs the Newton direction)."""
        X, lam = z[:-1].reshape(self.shape), float(z[-1])
        R, Jx = self.problem.residual(X, self.p(lam))
        Jl = self.column(z) if column is None else column
        return R.ravel(), np.column_stack([Jx, Jl])


def _tangent(G: np.ndarray, previous: np.ndarray | None) -> np.ndarray:
    """Unit null vector of the bordered Jacobian ``G`` (size x size + 1), oriented along
    ``previous`` (the shooting continuation's own construction)."""
    return _null_tangent(G[:, :-1], G[:, -1], previous)


def _correct(curve: _Curve, z_pred, t, tol, max_iter=10):
    """Newton on (R, t.(z - z_pred)); returns (z, iterations, G) with G the last bordered
    Jacobian (for the next tangent), or (None, iterations, None)."""
    z = z_pred.copy()
    try:
        column = curve.column(z_pred)
    except ValueError:  # values the model refuses (past the edge of the valid range)
        return None, 1, None
    for it in range(1, max_iter + 1):
        try:
            R, G = curve(z, column)
        except ValueError:
            return None, it, None
        if np.max(np.abs(R)) < tol and it > 1:
            return z, it - 1, G
        F = np.r_[R, t @ (z - z_pred)]
        if not np.all(np.isfinite(F)):
            return None, it, None
        try:
            dz = np.linalg.solve(np.vstack([G, t]), -F)
        except np.linalg.LinAlgError:
            return None, it, None
        z = z + dz
    return None, max_iter, None


def _point(curve: _Curve, z, t, stability: bool) -> HBPoint:
    X, lam = z[:-1].reshape(curve.shape), float(z[-1])
    sign = int(np.sign(t[-1])) or 1
    if not stability:
        return HBPoint(lam, X, None, None, None, sign)
    _, fl = hill(curve.problem, X, curve.p(lam))
    return HBPoint(lam, X, fl.multipliers, fl.stable, fl.stability, sign)


def monodromy_check(curve: _Curve, z, n: int) -> dict:
    """Hill's multipliers at ``z`` against the monodromy of the time integration from the
    harmonic-balance state (central differences of the flow over n T, compiled DOP853 at
    rtol 1e-12, the 2 n_states runs in one lockstep group): the largest distance from a
    Hill multiplier to the nearest monodromy multiplier."""
    from ..integrate.native import run_batch

    X, lam = z[:-1].reshape(curve.shape), float(z[-1])
    p = curve.p(lam)
    x0 = curve.problem.synthesis(X)[:, 0]
    nx = x0.size
    h = 1e-6 * max(1.0, float(np.max(np.abs(x0))))
    starts = np.vstack([x0 + h * e for e in np.eye(nx)] + [x0 - h * e for e in np.eye(nx)])
    run = run_batch(curve.system.module, np.repeat(p[None, :], 2 * nx, axis=0), starts,
                    method="dop853", rtol=1e-12, atol=1e-14, transient=0, periods=n,
                    samples_per_period=1)  # fmt: skip
    end = run.x[:, -1, :]
    M = ((end[:nx] - end[nx:]) / (2 * h)).T
    mu = np.linalg.eigvals(M)
    _, fl = hill(curve.problem, X, p)
    gap = max(float(np.min(np.abs(mu - m))) for m in fl.multipliers)
    return {"hill_vs_monodromy": gap, "max_monodromy_multiplier": float(np.max(np.abs(mu)))}


def _crit(point: HBPoint) -> float:
    return float(np.max(np.abs(point.multipliers))) - 1.0


def _kind(point: HBPoint) -> str:
    mu = point.multipliers[np.argmax(np.abs(point.multipliers))]
    if abs(mu.imag) > 1e-6:
        return "neimark-sacker"
    return "fold" if mu.real > 0 else "period-doubling"


def _locate(curve, z0, t0, ds, test, tol, stability) -> tuple[np.ndarray, HBPoint]:
    """The arclength step from (z0, t0) where ``test`` changes sign, by the Illinois
    variant of false position (Dowell and Jarratt 1971): the test functions (the tangent's
    parameter component, the critical multiplier's distance from the circle) are smooth
    in the step, so a few corrections do what forty bisections did."""
    a, b = 0.0, ds
    f_a = test(_point(curve, z0, t0, stability), t0)
    z_end, _, G = _correct(curve, z0 + b * t0, t0, tol)
    if z_end is None:
        return z0, None
    f_b = test(_point(curve, z_end, _tangent(G, t0), stability), _tangent(G, t0))
    z_best, p_best, side = z0, None, 0
    for _ in range(40):
        mid = b - f_b * (b - a) / (f_b - f_a) if f_b != f_a else 0.5 * (a + b)
        if not a < mid < b:
            mid = 0.5 * (a + b)
        z, _, G = _correct(curve, z0 + mid * t0, t0, tol)
        if z is None:
            break
        t = _tangent(G, t0)
        p = _point(curve, z, t, stability)
        f = test(p, t)
        z_best, p_best = z, p
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
        if b - a < 1e-10 * max(1.0, abs(ds)) or abs(f) < 1e-12:
            break
    return z_best, p_best


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
) -> HBBranch:
    """Continue the harmonic-balance solution from ``parameter = start`` to ``stop``.

    The first solution comes from :func:`harmonic_balance` (``guess`` as there).
    ``ds``: the first arclength step (default 1/200 of the range); ``ds_max`` its ceiling
    (default 1/20 of the range); ``dlam_max`` caps the parameter's change per step (the
    step is then at most ``dlam_max / |t_lambda|``: even resolution in the parameter
    where the curve runs straight, free steps where it turns).  Stops when the parameter
    leaves ``[start, stop]`` (the last point is solved at the end exactly), at the edge
    of its valid range (``_bounds.py``; a predictor that would cross it is shortened to
    land on it), or after ``max_points`` points; ``status`` and ``message`` say which.
    ``check``: every located event also carries the distance of Hill's multipliers from
    the monodromy of a time integration there (:func:`monodromy_check`).
    """
    import time

    started = time.perf_counter()
    if start == stop:
        raise ValueError(f"start and stop are both {start:g}: nothing to continue")
    valid = interval_of(system, parameter)
    if start not in valid:
        raise ValueError(f"{parameter} = {start:g}: outside its valid range {valid.rule()}")
    span = abs(stop - start)
    ds = ds or span / 200
    ds_max = ds_max or span / 20
    ds_min = span * 1e-9
    direction = 1.0 if stop > start else -1.0
    base = system.with_values(**{parameter: start})
    first = harmonic_balance(base, guess, harmonics=harmonics, n=n, samples=samples,
                             tol=tol, stability=False)  # fmt: skip
    problem = HarmonicBalance(system, harmonics, n, first.samples)
    curve = _Curve(system, parameter, problem)
    z = np.r_[first.coefficients.ravel(), float(start)]
    _, G = curve(z)
    t = _tangent(G, None)
    if t[-1] * direction < 0:
        t = -t
    points = [_point(curve, z, t, stability)]
    events: list[dict] = []
    notes: list[str] = []
    h = ds
    lo, hi = curve.valid.ends(start, stop)
    status, message = "max-points", f"stopped after {max_points} points"
    while len(points) < max_points:
        end = None
        if z[-1] + h * t[-1] not in curve.valid:
            # the predictor would cross the valid range's edge: land on the range's end
            end = hi if t[-1] > 0 else lo
            if abs(end - z[-1]) <= 1e-12 * max(1.0, abs(end)):
                status, message = ending(parameter, curve.valid, start, stop, lo, hi, end)
                break
            h = (end - z[-1]) / t[-1]
        z_new, iters, G = _correct(curve, z + h * t, t, tol)
        if z_new is None and end is None:
            h /= 2
            if h < ds_min:
                status = "stalled"
                message = (
                    f"stopped at {parameter} = {z[-1]:.6g}: the corrector failed "
                    "with the smallest step"
                )
                notes.append(message)
                break
            continue
        lam = float(z[-1] + h * t[-1]) if z_new is None else float(z_new[-1])
        if end is not None or not lo - 1e-12 <= lam <= hi + 1e-12:
            # the last point exactly at the end (natural parameter: lambda fixed)
            end = end if end is not None else hi if lam > hi else lo
            status, message = ending(parameter, curve.valid, start, stop, lo, hi, end)
            if status == "turned":
                notes.append(
                    f"the branch turned back and left the range at {parameter} = "
                    f"{end:g}; continue from there to follow it further"
                )
            sol = _at(curve, z if z_new is None else z_new, end, tol)
            if sol is not None:
                _, G = curve(sol)
                t_end = _tangent(G, t)
                points.append(_point(curve, sol, t_end, stability))
            break
        t_new = _tangent(G, t)
        p = _point(curve, z_new, t_new, stability)
        prev = points[-1]
        if locate and np.sign(t_new[-1]) != np.sign(t[-1]):
            # the tangent alone decides a fold: no Hill eigenproblem in the bisection
            zf, pf = _locate(curve, z, t, h, lambda q, tt: tt[-1], tol, False)
            if pf is not None:
                event = {"kind": "fold", parameter: pf.value, "index": len(points)}
                events.append(event | (monodromy_check(curve, zf, n) if check else {}))
        folded = (
            bool(events) and events[-1]["kind"] == "fold" and events[-1]["index"] == len(points)
        )
        changed = prev.multipliers is not None and prev.stable != p.stable
        if changed and folded and _kind(p if not p.stable else prev) == "fold":
            changed = False  # the fold located above is this change of stability
        if locate and stability and changed:
            zb, pb = _locate(curve, z, t, h, lambda q, tt: _crit(q), tol, stability)
            if pb is not None:
                kind = _kind(pb)
                near_fold = any(e["kind"] == "fold" and e["index"] == len(points) for e in events)
                if not (kind == "fold" and near_fold):
                    event = {"kind": kind, parameter: pb.value, "index": len(points)}
                    events.append(event | (monodromy_check(curve, zb, n) if check else {}))
        points.append(p)
        z, t = z_new, t_new
        h = min(ds_max, h * 1.5) if iters <= 3 else (h / 2 if iters > 6 else h)
        if dlam_max is not None and abs(t[-1]) > 0:
            h = min(h, dlam_max / abs(t[-1]))
    return HBBranch(
        system, parameter, n, harmonics, problem.N, tuple(points), tuple(events),
        time.perf_counter() - started, notes, status, message,
    )  # fmt: skip


def _at(curve: _Curve, z, lam: float, tol: float):
    """Newton in X at fixed ``lam`` from ``z``."""
    X = z[:-1].copy()
    p = curve.p(lam)
    for _ in range(20):
        R, J = curve.problem.residual(X.reshape(curve.shape), p)
        if np.max(np.abs(R)) < tol:
            return np.r_[X, lam]
        try:
            X = X - np.linalg.solve(J, R.ravel())
        except np.linalg.LinAlgError:
            return None
    return None
