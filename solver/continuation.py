"""Pseudo-arclength continuation of periodic orbits, with bifurcation detection.

Unknowns z = (x0, lambda): the orbit's state at tau = 0 (mod nT) and the parameter.
Each step predicts along the tangent t of the branch and corrects with Newton on

    ``G(x0, lambda) = phi_{nT}(x0; lambda) - x0 = 0``,   ``t . (z - z_pred) = 0``

(Keller's pseudo-arclength condition), so the branch is followed round folds.  dG/dx0 is
the monodromy minus I (automatic differentiation); dG/dlambda a central difference.  The
step adapts to Newton's effort.  Between two accepted points, sign changes of the test
functions

* ``det(M - I)``           -- fold (a multiplier through +1),
* ``det(M + I)``           -- period doubling (a multiplier through -1),
* ``prod over complex pairs (|mu|^2 - 1)`` -- Neimark-Sacker (a pair through the circle),

are located by bisection on the arclength.  At a period doubling the branch can be
switched onto the period-2n orbit (``switch_period_doubling``).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .flow import FlowMap
from .shooting import Floquet, ShootingError, floquet, shoot
from .system import System

__all__ = ["Bifurcation", "Branch", "continue_orbit", "switch_period_doubling"]


@dataclass(frozen=True)
class Bifurcation:
    kind: str  # "fold", "period-doubling", "neimark-sacker"
    value: float
    x0: np.ndarray
    multiplier: complex

    def describe(self) -> dict:
        return {"type": self.kind, "value": self.value,
                "multiplier": {"re": float(self.multiplier.real),
                               "im": float(self.multiplier.imag)},
                "x0": [float(v) for v in self.x0]}  # fmt: skip


@dataclass
class Branch:
    parameter: str
    n: int
    values: list = field(default_factory=list)
    states: list = field(default_factory=list)
    stable: list = field(default_factory=list)
    multipliers: list = field(default_factory=list)
    bifurcations: list = field(default_factory=list)
    message: str = ""

    def describe(self) -> dict:
        return {
            "parameter": self.parameter,
            "period_multiple": self.n,
            "values": [float(v) for v in self.values],
            "x0": [[float(v) for v in s] for s in self.states],
            "stable": [bool(s) for s in self.stable],
            "max_multiplier": [float(np.max(np.abs(m))) for m in self.multipliers],
            "bifurcations": [b.describe() for b in self.bifurcations],
            "message": self.message,
        }


class _Problem:
    """G, its Jacobian and the test functions at (x0, lambda) for one branch."""

    def __init__(self, system: System, parameter: str, n: int):
        self.base, self.parameter, self.n = system, parameter, n
        self.flows: dict[float, FlowMap] = {}

    def system(self, lam: float) -> System:
        return self.base.with_values(**{self.parameter: float(lam)})

    def _flow(self, lam):
        key = round(float(lam), 15)
        if key not in self.flows:
            if len(self.flows) > 64:
                self.flows.clear()
            self.flows[key] = FlowMap(self.system(lam))
        return self.flows[key]

    def G(self, x, lam) -> np.ndarray:
        sys = self.system(lam)
        return self._flow(lam)(x, self.n * sys.period) - x

    def jacobian(self, x, lam):
        sys = self.system(lam)
        xe, M, q = self._flow(lam).with_jacobian(x, self.n * sys.period)
        h = 1e-6 * max(1.0, abs(lam))
        dG = (self.G(x, lam + h) - self.G(x, lam - h)) / (2 * h)
        return xe - x, M, dG, q


def _tests(M: np.ndarray) -> np.ndarray:
    """Test functions (fold, period doubling, Neimark-Sacker) and the number of complex
    pairs, which must not change across a Neimark-Sacker point (where a pair merges into
    two real multipliers the product changes sign without any crossing of the circle)."""
    eye = np.eye(M.shape[0])
    mu = np.linalg.eigvals(M)
    complex_pairs = [m for m in mu if m.imag > 1e-9]
    ns = float(np.prod([abs(m) ** 2 - 1.0 for m in complex_pairs])) if complex_pairs else 1.0
    return np.array([np.linalg.det(M - eye), np.linalg.det(M + eye), ns, len(complex_pairs)])


_KINDS = ("fold", "period-doubling", "neimark-sacker")


def _tangent(Gx, Gl, previous=None) -> np.ndarray:
    A = np.hstack([Gx, Gl[:, None]])
    if previous is None:
        t = np.linalg.svd(A)[2][-1]
    else:
        t = np.linalg.solve(np.vstack([A, previous[None, :]]),
                            np.concatenate([np.zeros(A.shape[0]), [1.0]]))  # fmt: skip
    return t / np.linalg.norm(t)


def _correct(prob: _Problem, z_pred, t, tol=1e-10, max_iter=8):
    z = z_pred.copy()
    for it in range(1, max_iter + 1):
        G, M, dG, q = prob.jacobian(z[:-1], z[-1])
        N = z.size - 1
        H = np.concatenate([G, [t @ (z - z_pred)]])
        if np.max(np.abs(H)) < tol and it > 1:
            return z, it, M, q, dG
        A = np.vstack([np.hstack([M - np.eye(N), dG[:, None]]), t[None, :]])
        z = z - np.linalg.solve(A, H)
    G, M, dG, q = prob.jacobian(z[:-1], z[-1])
    if max(np.max(np.abs(G)), abs(t @ (z - z_pred))) < tol:
        return z, max_iter, M, q, dG
    raise ShootingError("corrector did not converge", [])


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

    The first orbit is found by shooting; the branch ends at ``stop``, after
    ``max_points`` points, or when the step falls below ``ds_min``.
    """
    if not (ds > 0 and ds_min > 0 and ds_max >= ds_min):
        raise ValueError(f"steps must be positive (ds = {ds}, ds_min = {ds_min}, "
                         f"ds_max = {ds_max})")  # fmt: skip
    if n < 1:
        raise ValueError(f"the period multiple n must be >= 1, got {n}")
    prob = _Problem(system, parameter, n)
    first = shoot(prob.system(start), x0, n)
    z = np.concatenate([first.x0, [start]])
    G, M, dG, q = prob.jacobian(z[:-1], z[-1])
    t = _tangent(M - np.eye(M.shape[0]), dG)
    direction = np.sign(stop - start) or 1.0
    if np.sign(t[-1]) != direction:
        t = -t
    branch = Branch(parameter, n)
    fl = floquet(M, q)

    def record(z, fl: Floquet):
        branch.values.append(float(z[-1]))
        branch.states.append(z[:-1].copy())
        branch.stable.append(fl.stable)
        branch.multipliers.append(fl.multipliers)

    record(z, fl)
    tests = _tests(M)
    lo, hi = min(start, stop), max(start, stop)
    while len(branch.values) < max_points:
        try:
            z_new, iters, M_new, q_new, dG_new = _correct(prob, z + ds * t, t)
        except (ShootingError, np.linalg.LinAlgError, RuntimeError, ValueError):
            # ValueError: the step reached parameter values the model refuses (omega <= 0).
            ds /= 2
            if ds < ds_min:
                branch.message = f"step fell below {ds_min:g} at {parameter} = {z[-1]:.6g}"
                break
            continue
        t_new = _tangent(M_new - np.eye(M_new.shape[0]), dG_new, t)
        tests_new = _tests(M_new)
        for k, kind in enumerate(_KINDS):
            if np.sign(tests_new[k]) == np.sign(tests[k]) or tests[k] == 0:
                continue
            if kind == "neimark-sacker" and tests_new[3] != tests[3]:
                continue  # complex pairs merged or split on the real axis: no crossing
            found = _locate(prob, z, t, ds, k, kind, tests[k], locate_tol)
            if kind != "neimark-sacker" or abs(abs(found.multiplier) - 1.0) < 1e-3:
                branch.bifurcations.append(found)
        if not lo - 1e-12 <= z_new[-1] <= hi + 1e-12:
            # Land on the end of the range: shoot at the end value from the state
            # interpolated between the last two points (the point past it is not kept).
            end = hi if z_new[-1] > hi else lo
            w = (end - z[-1]) / (z_new[-1] - z[-1]) if z_new[-1] != z[-1] else 1.0
            try:
                last = shoot(prob.system(end), z[:-1] + w * (z_new[:-1] - z[:-1]), n)
                record(np.concatenate([last.x0, [end]]), last.floquet)
            except (ShootingError, ValueError, RuntimeError):
                pass
            branch.message = f"reached the end of [{lo:g}, {hi:g}]"
            break
        z, t, tests = z_new, t_new, tests_new
        record(z, floquet(M_new, q_new))
        ds = min(ds * 1.5, ds_max) if iters <= 3 else max(ds / 1.5, ds_min)
    else:
        branch.message = f"stopped after {max_points} points"
    return branch


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
        f = _tests(M)[k]
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


def switch_period_doubling(system: System, parameter: str, bif: Bifurcation, n: int,
                           stop: float, offset: float = 0.01, **kwargs) -> Branch:  # fmt: skip
    """Start the period-2n branch born at a period doubling and continue it toward
    ``stop``.

    A little past the bifurcation (``offset`` in the parameter) the new orbit lies about
    sqrt(offset) away along the eigenvector of the -1 multiplier.  It is looked for by
    simulation from there (a supercritical doubling gives a stable period-2n orbit) and
    then by shooting from guesses along the eigenvector on either side; an orbit counts
    only if it is not the period-n one.
    """
    from .simulate import simulate

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
            run = simulate(here, bif.x0 + np.sqrt(step) * v, method="cvodes", transient=300,
                           periods=2 * n)  # fmt: skip
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
                    x_start = FlowMap(here)(orbit.x0, (-orbit.t0) % (2 * n * here.period),
                                            orbit.t0)  # fmt: skip
                end = stop if side == toward else bif.value + side * abs(stop - bif.value)
                return continue_orbit(system, parameter, lam, end, x_start, n=2 * n, **kwargs)
    raise ShootingError(
        f"no period-{2 * n} orbit found next to the period doubling at "
        f"{parameter} = {bif.value:.6g}",
        tried,
    )
