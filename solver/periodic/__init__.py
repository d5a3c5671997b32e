"""Periodic orbits, split along the mathematics.

* ``flow.py`` -- the flow map and its derivative (AD, variational, finite differences),
  and the stroboscopic map as an object of its own;
* ``shooting.py`` -- single and multiple shooting as a pure residual ``G(X, T, p)``;
* ``newton.py`` -- the one (damped) Newton solver;
* ``floquet.py`` -- multipliers, stability, Liouville's check, bifurcation test functions;
* ``engine.py`` -- the one pseudo-arclength continuation engine (predictor, corrector,
  step control, folds, period doublings and Neimark-Sacker points located) for any
  problem that states its residual, Jacobian and stability; ``records.py`` -- the one
  branch record and the one bifurcation record it returns;
* ``continuation.py`` -- the shooting problem on the stroboscopic map and
  ``continue_orbit``;
* ``switching.py`` -- branch switching at a period doubling;
* ``harmonic_balance.py`` -- harmonic balance by alternating frequency-time with the
  generated Jacobian; ``hill.py`` -- Hill's stability; ``hb_continuation.py`` -- the
  harmonic-balance problem on the Fourier coefficients and ``continue_hb``.
"""

from .continuation import continue_orbit
from .floquet import Floquet, bifurcation_tests, floquet
from .flow import MONODROMY_METHODS, FlowMap, StroboscopicMap, monodromy_agreement
from .harmonic_balance import (
    HarmonicBalance,
    HarmonicBalanceError,
    HBSolution,
    harmonic_balance,
    hill,
)
from .newton import NewtonError, NewtonResult, newton
from .records import Bifurcation, Branch, BranchPoint
from .shooting import Orbit, OrbitSearch, ShootingError, residual, search, shoot
from .switching import switch_period_doubling

__all__ = [
    "MONODROMY_METHODS",
    "Bifurcation",
    "Branch",
    "BranchPoint",
    "Floquet",
    "FlowMap",
    "HBSolution",
    "HarmonicBalance",
    "HarmonicBalanceError",
    "NewtonError",
    "NewtonResult",
    "Orbit",
    "OrbitSearch",
    "ShootingError",
    "StroboscopicMap",
    "bifurcation_tests",
    "continue_orbit",
    "floquet",
    "harmonic_balance",
    "hill",
    "monodromy_agreement",
    "newton",
    "residual",
    "search",
    "shoot",
    "switch_period_doubling",
]
