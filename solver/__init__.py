"""gearsym.solver -- non-dimensional analysis on the generated models.

The solver knows a model only through the generated module's interface (``STATES``,
``PARAMETERS``, ``parameters()``, ``rhs``, ``jacobian``, ``casadi_functions``).

* :class:`System` -- a model with parameter values;
* :func:`simulate` -- one front door for time integration, back ends by name;
* :func:`analyse_point` -- response, spectra, largest Lyapunov exponent, motion type;
* :func:`sweep` -- bifurcation sweeps with forward/backward continuation.
"""

from ._models import load_generated
from .point import PointResult, analyse_point
from .simulate import METHODS, SimulationError, Trajectory, simulate
from .sweep import SweepResult, sweep
from .system import System

__all__ = [
    "METHODS",
    "PointResult",
    "SimulationError",
    "SweepResult",
    "System",
    "Trajectory",
    "analyse_point",
    "load_generated",
    "simulate",
    "sweep",
]
