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

from dataclasses import dataclass, field

import numpy as np

from ..system import System
from .continuation import _tangent as _null_tangent
from .harmonic_balance import HarmonicBalance, harmonic_balance, hill

__all__ = ["HBBranch", "HBPoint", "continue_hb"]


@dataclass(frozen=True)
class HBPoint:
    value: float
    coefficients: np.ndarray  # (states, 2H + 1)
    multipliers: np.ndarray | None
    stable: bool | None
    stability: str | None
    tangent_sign: int  # sign of d(parameter)/d(arclength)


@dataclass(frozen=True)
class HBBranch:
    """A continued branch of harmonic-balance solutions, in the order of arclength, and
    the folds and stability changes located on it."""

    system: System
    parameter: str
    n: int
    harmonics: int
    samples: int
    points: tuple[HBPoint, ...]
    events: tuple[dict, ...] = ()
    wall_time: float = 0.0
    notes: list = field(default_factory=list)

    @property
    def values(self) -> np.ndarray:
        return np.array([p.value for p in self.points])

    @property
    def stable(self) -> np.ndarray:
        return np.array([bool(p.stable) for p in self.points])

    def _problem(self) -> HarmonicBalance:
        return HarmonicBalance(self.system, self.harmonics, self.n, self.samples)

    def series(self, name: str, points: int = 512) -> np.ndarray:
        """``name`` over one period at every point, (len, points)."""
        i = self.system.index(name)
        s = 2 * np.pi * np.arange(points) / points
        prob = self._problem()
        C = np.array([p.coefficients[i] for p in self.points])
        return prob.time_series(C, s)

    def mean(self, name: str) -> np.ndarray:
        i = self.system.index(name)
        return np.array([p.coefficients[i, 0] for p in self.points])

    def amplitude(self, name: str) -> np.ndarray:
        """Half peak-to-peak of ``name`` at every point."""
        y = self.series(name)
        return (y.max(axis=1) - y.min(axis=1)) / 2

    def maximum(self, name: str) -> np.ndarray:
        return self.series(name).max(axis=1)

    def minimum(self, name: str) -> np.ndarray:
        return self.series(name).min(axis=1)

    def rms(self, name: str) -> np.ndarray:
        i = self.system.index(name)
        C = np.array([p.coefficients[i] for p in self.points])
        return np.sqrt(C[:, 0] ** 2 + 0.5 * np.sum(C[:, 1:] ** 2, axis=1))

    def tail_shares(self, top: int | None = None) -> np.ndarray:
        """Per point, the largest share (RMS sense, over the coordinates) of the response
        that the highest ``top`` harmonics carry (default a quarter of H)."""
        top = top or max(1, self.harmonics // 4)
        out = np.zeros(len(self.points))
        for c in self.system.coordinates:
            i = self.system.index(c)
            C = np.array([p.coefficients[i, 1:] for p in self.points])
            a2 = C[:, 0::2] ** 2 + C[:, 1::2] ** 2
            total = a2.sum(axis=1)
            share = np.sqrt(np.divide(a2[:, -top:].sum(axis=1), total, out=np.zeros_like(total),
                                      where=total > 0))  # fmt: skip
            out = np.maximum(out, share)
        return out

    def records(self) -> list[dict]:
        """One record per solution point: the parameter under its own name, ``stable``,
        and per coordinate its ``mean``, ``amplitude`` (half peak-to-peak) and ``rms``."""
        coords = self.system.coordinates
        stats = {c: (self.mean(c), self.amplitude(c), self.rms(c)) for c in coords}
        out = []
        for k, p in enumerate(self.points):
            rec = {self.parameter: p.value, "stable": p.stable, "stability": p.stability}
            for c in coords:
                m, a, r = stats[c]
                rec[c] = {"mean": float(m[k]), "amplitude": float(a[k]), "rms": float(r[k])}
            out.append(rec)
        return out


class _Curve:
    """R(X, lambda) and its Jacobians for one parameter."""

    def __init__(self, system: System, parameter: str, problem: HarmonicBalance):
        self.system, self.parameter, self.problem = system, parameter, problem
        self.shape = (system.n, problem.M)
        self.size = system.n * problem.M
        system.parameters_with(**{parameter: system.parameter(parameter)})  # name checked

    def p(self, lam: float) -> np.ndarray:
        return self.system.parameters_with(**{self.parameter: lam})

    def column(self, z) -> np.ndarray:
        """dR/d(lambda) by a central difference."""
        X, lam = z[:-1].reshape(self.shape), float(z[-1])
        h = 1e-7 * max(1.0, abs(lam))
        up = self.problem.residual(X, self.p(lam + h), jacobian=False)[0]
        dn = self.problem.residual(X, self.p(lam - h), jacobian=False)[0]
        return ((up - dn) / (2 * h)).ravel()

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
    column = curve.column(z_pred)
    for it in range(1, max_iter + 1):
        R, G = curve(z, column)
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
    leaves ``[start, stop]`` (the last point is solved at ``stop`` exactly) or after
    ``max_points`` points.  ``check``: every located event also carries the distance of
    Hill's multipliers from the monodromy of a time integration there
    (:func:`monodromy_check`).
    """
    import time

    started = time.perf_counter()
    if start == stop:
        raise ValueError(f"start and stop are both {start:g}: nothing to continue")
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
    lo, hi = min(start, stop), max(start, stop)
    while len(points) < max_points:
        z_new, iters, G = _correct(curve, z + h * t, t, tol)
        if z_new is None:
            h /= 2
            if h < ds_min:
                notes.append(f"stopped at {parameter} = {z[-1]:.6g}: the corrector failed "
                             "with the smallest step")  # fmt: skip
                break
            continue
        lam = float(z_new[-1])
        if not lo - 1e-12 <= lam <= hi + 1e-12:
            # the last point exactly at the end (natural parameter: lambda fixed)
            end = stop if abs(lam - stop) <= abs(lam - start) else start
            if end == start:
                notes.append(f"the branch turned back and left the range at {parameter} = "
                             f"{start:g}; continue from there to follow it further")  # fmt: skip
            sol = _at(curve, z, end, tol)
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
        time.perf_counter() - started, notes,
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
