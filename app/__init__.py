"""gearsym -- gear-train nonlinear dynamics: derive the equations, generate code, analyse.

The public API (see ``docs/api.md``)::

    import gearsym

    system = gearsym.load("reference-light", **{"lambda": 0.8})   # scene, topology or path
    point = gearsym.analyse(system)                  # response, exponent, motion type
    orbit = gearsym.shoot(system, point.trajectory.poincare[:, 0])  # periodic orbit
    branch = gearsym.continue_orbit(system, "lambda", 0.8, 1.0, orbit.x0)
    bif = gearsym.sweep(system, "lambda", [0.1, 0.5, 0.9])           # bifurcation sweep

Rooms: ``gearsym.derive`` (SymPy, SI), ``gearsym.solver`` (non-dimensional numerics),
``gearsym.generated`` (emitted code), and this application layer: the scene resolver
(``gearsym.resolve``), the CLI (``gearsym.cli``) and the studies (``gearsym.studies``).
"""

from gearsym.derive import InputError, derive_model, load_target
from gearsym.solver import (
    METHODS,
    Branch,
    Contract,
    FlowMap,
    Orbit,
    PointResult,
    ShootingError,
    SimulationError,
    StroboscopicMap,
    SweepPoint,
    SweepResult,
    System,
    Trajectory,
    continue_orbit,
    shoot,
    simulate,
    sweep,
    switch_period_doubling,
)
from gearsym.solver import analyse_point as analyse
from gearsym.solver.export import save

from .resolve import load

__version__ = "0.1.0"

__all__ = [
    "METHODS",
    "Branch",
    "Contract",
    "FlowMap",
    "InputError",
    "Orbit",
    "PointResult",
    "ShootingError",
    "SimulationError",
    "StroboscopicMap",
    "SweepPoint",
    "SweepResult",
    "System",
    "Trajectory",
    "analyse",
    "continue_orbit",
    "derive_model",
    "load",
    "load_target",
    "save",
    "shoot",
    "simulate",
    "sweep",
    "switch_period_doubling",
]
