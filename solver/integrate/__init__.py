"""Time integration: one front door (:func:`simulate`), methods by name, one event loop.

* ``methods.py`` -- the registry of frozen method records;
* ``simulate.py`` -- the front door and the :class:`Trajectory` it returns;
* ``result.py`` -- the request every back end takes and the run it returns;
* ``scipy_backend.py``, ``casadi_backend.py``, ``native/`` -- the back ends;
* ``events.py`` -- the one loop that stops and restarts at switching surfaces;
* ``variational.py`` -- the variational equations, built once for every caller;
* ``tableau.py`` -- checked Butcher tableaux and the generic explicit step.
"""

from .events import SimulationError
from .methods import METHODS, Method, get_method
from .simulate import Trajectory, default_initial_state, fastest_method, simulate

__all__ = [
    "METHODS",
    "Method",
    "SimulationError",
    "Trajectory",
    "default_initial_state",
    "fastest_method",
    "get_method",
    "simulate",
]
