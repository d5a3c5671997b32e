"""Is the run on a periodic orbit?  The shooting check a period-n verdict rests on.

From the run's last Poincare point ``x`` (time ``t``, a whole number of forcing periods),
Newton's method solves

    ``G(x) = phi_{nT}(x; t) - x = 0``,   ``x <- x - (M - I)^{-1} G(x)``,

with the flow ``phi`` and the monodromy ``M = d phi_{nT} / dx`` both from the one engine
(``integrate()``, DOP853 at ``rtol = 1e-12``, the ``N`` or ``2 N + 1`` runs of an
iteration in one batch):

* a smooth force law: ``M`` from the variational equations, one tangent per state started
  from its unit vector; its entries carry about the integration's error (against central
  differences of the flow, 1e-7 relative: the differences' own error);
* a piecewise one whose kinks the integrator locates (the dead zone of a mesh coordinate):
  central differences of the flow with steps
  ``h_i = 1e-5 max(1, |x_i|)``, as before the variational route.  The tangent's vector
  field jumps at every kink and the flow is only once differentiable there; near a
  grazing contact neither route settles (on the reference dead-zone model, one period
  from (0.9, 0.7, 0.1, -0.2), entries move by up to 5 % with the tolerance or the step,
  the tangent's between two values, 0.43608 and 0.43627 for the first).

* a piecewise one whose kinks lie on no coordinate (a planetary set's meshes: the
  contract's ``switching_rows``, not located): the variational equations, whose jumps the
  adaptive steps take as the differences' runs would, at a fifth of the runs.

The multipliers' stated error ``mu_error`` (1e-6) is that of the differences on a smooth
flow, ``h^2 + rtol / h`` with a margin; near a kink it can be larger, as said.  Converged
when ``|G|`` is below ``tol max(1, |x|)``.

The orbit found is then checked as the verdict needs it:

* its **minimal period**: the smallest divisor m of n with ``|phi_{mT}(x*) - x*|`` below
  ``1e3 tol`` of the state's size (a period-2 guess may converge to a period-1 orbit);
* its **multipliers** (eigenvalues of M at the converged state) and whether the orbit
  attracts: ``max |mu| < 1 - mu_error``;
* its **distance** from the run's point (max-norm): how far the run still was from it.

Written for the verdict of ``verdict.py``; ``periodic/shooting.py`` is the user-facing
shooting (CasADi flow, automatic differentiation, multiple shooting), an independent
route that the tests compare this one against.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..integrate.run import Batch, integrate
from ..integrate.spec import RunSpec
from ..system import System

__all__ = ["OrbitCheck", "check_orbit"]

_H = 1e-5  # relative step of the central differences (piecewise force laws)
_MU_ERROR = 1e-6  # the multipliers' stated error (see the module text), with a margin
# a multiplier at +1 to rounding: a family's (flat along it); a fold's multiplier is within
# 1e-9 of 1 only some 1e-18 of its parameter from the fold
_NEUTRAL = 1e-9


@dataclass(frozen=True)
class OrbitCheck:
    """What the shooting check found for period multiple ``n``.

    ``x`` is the orbit's state at the run's section (None: no convergence, ``why`` says
    why); ``multipliers`` are its Floquet multipliers of the period ``n T``.
    """

    n: int
    converged: bool
    x: np.ndarray | None = None
    residual: float = float("inf")
    iterations: int = 0
    minimal_period: int | None = None
    multipliers: np.ndarray | None = None
    distance: float = float("inf")
    why: str = ""
    method: str = "Newton shooting, variational monodromy, DOP853 at rtol 1e-12"

    @property
    def largest(self) -> float:
        """The largest multiplier modulus (inf when unknown)."""
        if self.multipliers is None or not self.multipliers.size:
            return float("inf")
        return float(np.max(np.abs(self.multipliers)))

    @property
    def attracting(self) -> bool:
        """Converged, of minimal period n, and every multiplier inside the unit circle by
        more than the multipliers' error."""
        return self.converged and self.minimal_period == self.n and self.largest < 1 - _MU_ERROR

    @property
    def neutral(self) -> bool:
        """Converged, of minimal period n, every multiplier inside the unit circle by more
        than their error but one or more at +1 to rounding (:data:`_NEUTRAL`): the orbit is
        one of a family (a free motion, such as bodies turning inside their backlash with
        every mesh apart, where the flow is flat along the family and the multiplier is 1
        exactly), which neither attracts nor repels along it.  A saddle-node orbit has a
        multiplier near +1 too, but only at the fold itself does it reach 1; within the
        multipliers' error of it (1e-6) it is still a lone orbit, stable or not."""
        if not (self.converged and self.minimal_period == self.n) or self.multipliers is None:
            return False
        mu = np.asarray(self.multipliers)
        on = np.abs(mu - 1.0) <= _NEUTRAL
        return bool(on.any() and np.all(np.abs(mu[~on]) < 1 - _MU_ERROR))

    def exponent(self, period: float) -> float:
        """The largest Lyapunov exponent of the orbit, ``log max|mu| / (n T)``, per tau."""
        return float(np.log(self.largest) / (self.n * period))

    def describe(self) -> dict:
        mu = [] if self.multipliers is None else self.multipliers
        return {
            "n": self.n,
            "converged": self.converged,
            "minimal_period": self.minimal_period,
            "residual": self.residual,
            "iterations": self.iterations,
            "distance_from_run": self.distance,
            "multipliers": [[float(m.real), float(m.imag)] for m in mu],
            "largest_multiplier": None if self.multipliers is None else self.largest,
            "multiplier_error": _MU_ERROR,
            "attracting": self.attracting,
            **({"neutral": True} if self.neutral else {}),
            "method": self.method,
            **({"why": self.why} if self.why else {}),
            **(
                {
                    "multiplier_error_note": "that of the differences on a smooth flow; "
                    "near a grazing contact of the piecewise force law it can be larger "
                    "(orbit_check.py)"
                }
                if self.method != _METHODS["smooth"]
                else {}
            ),
        }


_METHODS = {
    "smooth": "Newton shooting, variational monodromy, DOP853 at rtol 1e-12",
    "located": "Newton shooting, central-difference monodromy, DOP853 at rtol 1e-12",
    "unlocated": "Newton shooting, variational monodromy through the unlocated kinks of the "
    "meshes, DOP853 at rtol 1e-12",
}


def _route(system: System) -> str:
    """How the monodromy is found (module text): ``smooth``, ``located`` or ``unlocated``."""
    if not system.piecewise:
        return "smooth"
    return "located" if system.contract.switching_surfaces else "unlocated"


def _flow(system: System, x: np.ndarray, n: int, t0: float, spec: RunSpec):
    """``phi_{mT}(x)`` for m = 0..n, shape (n + 1, N), and the monodromy ``d phi_{nT} /
    dx`` (N, N), by the route the module text gives for the force law."""
    spec = spec.with_(t0=t0, periods=n, lyapunov_periods=n)
    if _route(system) != "located":
        res = integrate(system, x, spec)
        if res.status[0] != "ok":
            raise FloatingPointError(f"the flow stopped: {res.status[0]}")
        return res.x[0], res.monodromy[0]
    h = _H * np.maximum(1.0, np.abs(x))
    X = np.vstack([x, x + np.diag(h), x - np.diag(h)])
    batch = Batch.of(system.module, np.repeat(system.p[None, :], X.shape[0], axis=0))
    res = integrate(batch, X, spec.with_(collect=("samples", "exponent")))
    bad = [s for s in res.status if s != "ok"]
    if bad:
        raise FloatingPointError(f"the flow stopped: {bad[0]}")
    N = system.n
    return res.x[0], (res.x[1 : N + 1, -1] - res.x[N + 1 :, -1]).T / (2.0 * h)


def check_orbit(
    system: System,
    x,
    n: int,
    *,
    t0: float = 0.0,
    tol: float = 1e-9,
    max_iter: int = 8,
) -> OrbitCheck:
    """Newton shooting for a period-``n`` orbit from the run's state ``x`` at time ``t0``
    (tau), checked as the module text says.  Never raises for a failed integration or a
    singular step: the check then did not converge and ``why`` says so."""
    x = np.asarray(x, dtype=float).copy()
    start = x.copy()
    N = system.n
    phase0 = float(np.mod(system.omega * t0, 2.0 * np.pi))
    spec = RunSpec(
        method="dop853",
        rtol=1e-12,
        atol=1e-14,
        time="phase",
        transient=0,
        periods=n,
        valid_range="ignore",
        bound=1e6,
        # the monodromy by the state and its matrix of tangents in one run (run.py); the
        # differences' runs take the library with one tangent, as a map's runs and the
        # continued windows do
        collect=("samples", "exponent", "monodromy"),
        lyapunov_periods=n,
    )
    residual = float("inf")
    how = {"method": _METHODS[_route(system)]}
    for it in range(max_iter + 1):
        try:
            path, M = _flow(system, x, n, phase0, spec)
        except FloatingPointError as err:
            return OrbitCheck(n, False, residual=residual, iterations=it, why=str(err), **how)
        G = path[-1] - x
        residual = float(np.max(np.abs(G)))
        scale = max(1.0, float(np.max(np.abs(x))))
        if residual <= tol * scale:
            return _found(system, x, n, path, M, residual, it, start)
        if it == max_iter:
            break
        try:
            step = np.linalg.solve(M - np.eye(N), -G)
        except np.linalg.LinAlgError:
            return OrbitCheck(
                n, False, residual=residual, iterations=it, why="singular step", **how
            )
        if not np.all(np.isfinite(step)) or np.max(np.abs(step)) > 0.5 * scale:
            why = "the Newton step left the run's neighbourhood"
            return OrbitCheck(n, False, residual=residual, iterations=it, why=why, **how)
        x = x + step
    why = f"no convergence in {max_iter}"
    return OrbitCheck(n, False, residual=residual, iterations=max_iter, why=why, **how)


def _found(system, x, n, path, M, residual, iterations, start) -> OrbitCheck:
    """The converged orbit with its minimal period, multipliers and distance."""
    scale = max(1.0, float(np.max(np.abs(x))))
    minimal = n
    for m in range(1, n):
        if n % m == 0 and np.max(np.abs(path[m] - x)) <= 1e-6 * scale:
            minimal = m
            break
    return OrbitCheck(
        n,
        True,
        x.copy(),
        residual,
        iterations,
        minimal,
        np.linalg.eigvals(M),
        float(np.max(np.abs(x - start))),
        method=_METHODS[_route(system)],
    )
