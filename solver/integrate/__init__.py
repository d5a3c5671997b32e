"""Time integration: one front door (:func:`simulate`), methods by name, one event loop.

* ``methods.py`` -- the registry of frozen method records;
* ``simulate.py`` -- the front door and the :class:`Trajectory` it returns;
* ``spec.py``, ``run.py`` -- batched runs: :func:`integrate` of a :class:`RunSpec` on one
  point or a :class:`Batch`, by the compiled engine or its one fallback, to a
  :class:`RunResult`;
* ``result.py`` -- the request every back end takes and the run it returns;
* ``scipy_backend.py``, ``casadi_backend.py``, ``native/`` -- the back ends;
* ``events.py`` -- the one loop that stops and restarts at switching surfaces;
* ``variational.py`` -- the variational equations, built once for every caller;
* ``tableau.py`` -- checked Butcher tableaux and the generic explicit step.
"""

from .events import SimulationError
from .methods import METHODS, Method, get_method
from .run import Batch, integrate
from .simulate import Trajectory, default_initial_state, fastest_method, simulate
from .spec import RunResult, RunSpec

__all__ = [
    "METHODS",
    "Batch",
    "Method",
    "RunResult",
    "RunSpec",
    "SimulationError",
    "Trajectory",
    "default_initial_state",
    "fastest_method",
    "get_method",
    "integrate",
    "simulate",
]
