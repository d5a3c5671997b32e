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

import importlib as _importlib

# Names resolve on first use (PEP 562): a sweep does not load the periodic-orbit code and
# SciPy's linear algebra that it never calls.  ``gearsym.solver.sweep`` is the sub-package;
# the function is ``gearsym.solver.sweep.sweep`` (and ``gearsym.sweep``).
_EXPORTS = {
    "PointResult": "analysis",
    "analyse_point": "analysis",
    "Contract": "contract",
    "load_generated": "contract",
    "METHODS": "integrate",
    "SimulationError": "integrate",
    "Trajectory": "integrate",
    "simulate": "integrate",
    "Branch": "periodic",
    "FlowMap": "periodic",
    "Orbit": "periodic",
    "ShootingError": "periodic",
    "StroboscopicMap": "periodic",
    "continue_orbit": "periodic",
    "shoot": "periodic",
    "switch_period_doubling": "periodic",
    "SweepPoint": "sweep",
    "SweepResult": "sweep",
    "System": "system",
}


def __getattr__(name: str):
    if name not in _EXPORTS:
        raise AttributeError(f"module 'gearsym.solver' has no attribute {name!r}")
    module = _importlib.import_module(f".{_EXPORTS[name]}", __name__)
    value = getattr(module, name)
    globals()[name] = value
    return value


def __dir__():
    return sorted(set(globals()) | set(_EXPORTS))


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
    "switch_period_doubling",
]
