"""gearsym.solver -- non-dimensional analysis on the generated models.

The solver knows a model only through the generated module's contract (``contract.py``)
and its functions; it never imports ``gearsym.derive``.  Rooms:

* ``system.py`` -- :class:`System`, a generated module with parameter values;
* ``integrate/`` -- :func:`simulate`, the method registry, the back ends, the event loop;
* ``periodic/`` -- flow and stroboscopic maps, shooting, Newton, Floquet, continuation;
* ``analysis/`` -- spectra, classification, Lyapunov exponent, one operating point;
* ``sweep/`` -- sweeps, their store, the one executor;
* ``plots.py`` -- figures from result objects.
"""

from .analysis import PointResult, analyse_point
from .contract import Contract, load_generated
from .integrate import METHODS, SimulationError, Trajectory, simulate
from .periodic import (
    Branch,
    FlowMap,
    Orbit,
    ShootingError,
    StroboscopicMap,
    continue_orbit,
    shoot,
    switch_period_doubling,
)
from .sweep import SweepPoint, SweepResult, sweep
from .system import System

__all__ = [
    "METHODS",
    "Branch",
    "Contract",
    "FlowMap",
    "Orbit",
    "PointResult",
    "ShootingError",
    "SimulationError",
    "StroboscopicMap",
    "SweepPoint",
    "SweepResult",
    "System",
    "Trajectory",
    "analyse_point",
    "continue_orbit",
    "load_generated",
    "shoot",
    "simulate",
    "sweep",
    "switch_period_doubling",
]
