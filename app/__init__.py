"""gearsym -- gear-train nonlinear dynamics: derive the equations, generate code, analyse.

The public API (see ``docs/api.md``)::

    import gearsym

    system = gearsym.load("reference-light", **{"lambda": 0.8})   # scene, topology or path
    point = gearsym.analyse(system)                  # response, exponent, motion type
    orbit = gearsym.shoot(system, point.trajectory.poincare[:, 0])  # periodic orbit
    branch = gearsym.continue_orbit(system, "lambda", 0.8, 1.0, orbit.x0)
    bif = gearsym.sweep(system, "lambda", [0.1, 0.5, 0.9])           # bifurcation sweep
    modal = gearsym.modes(gearsym.load("diso-bearings-light"))       # natural frequencies
    fig = gearsym.plot.bifurcation(bif)                              # a matplotlib Figure

Every command of the CLI has its function here: ``simulate``/``analyse`` (simulate),
``sweep``, ``regime_map`` (map), ``shoot``, ``continue_orbit`` (continue),
``frequency_response`` (with ``harmonic_balance`` and ``continue_hb``), ``modes`` (of a
planetary set ``planetary.modes`` and ``planetary.parametric_instabilities``),
``fit_dead_zone`` (backlash), ``derive_model`` (derive), ``reproduce``; ``gearsym.plot``
draws their results.

Rooms: ``gearsym.derive`` (SymPy, SI), ``gearsym.solver`` (non-dimensional numerics),
``gearsym.generated`` (emitted code), and this application layer: the scene resolver
(``gearsym.resolve``), the CLI (``gearsym.cli``) and the studies (``gearsym.studies``).
"""

import importlib as _importlib

# Names resolve on first use (PEP 562), so that `gearsym <command>` imports only what the
# command needs: a sweep of a shipped scene never loads SymPy or the derivation.
_EXPORTS = {
    "InputError": "gearsym.derive.input.reader",
    "derive_model": "gearsym.derive",
    "load_target": "gearsym.derive",
    "save": "gearsym.solver.export",
    "load": "gearsym.resolve",
    "analyse": ("gearsym.solver", "analyse_point"),
    "sweep": ("gearsym.solver.sweep", "sweep"),
    "harmonic_balance": "gearsym.solver.periodic.harmonic_balance",
    "continue_hb": "gearsym.solver.periodic.hb_continuation",
    "frequency_response": "gearsym.solver.sweep.frequency",
    "modes": "gearsym.solver.analysis.modes",
    "planetary": ("gearsym.planetary", None),  # the module: planetary sets
    "Modes": "gearsym.solver.analysis.modes",
    "FrequencyResponse": "gearsym.solver.sweep.frequency_result",
    "regime_map": "gearsym.solver.sweep.atlas",
    "RegimeMap": "gearsym.solver.sweep.maps_result",
    "fit_dead_zone": "gearsym.derive",
    "reproduce": "gearsym.studies.reproduce",
    "plot": ("gearsym.plot", None),  # the module itself: the figures
    "Units": "gearsym.solver.units",
    "in_units": "gearsym.solver.units_table",
    "orbit_in_units": "gearsym.solver.units",
    **{
        name: "gearsym.solver"
        for name in (
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
            "continue_orbit",
            "shoot",
            "simulate",
            "switch_period_doubling",
        )
    },
}


def __getattr__(name: str):
    where = _EXPORTS.get(name)
    if where is None:
        raise AttributeError(f"module 'gearsym' has no attribute {name!r}")
    module, attr = where if isinstance(where, tuple) else (where, name)
    value = _importlib.import_module(module)
    value = value if attr is None else getattr(value, attr)
    globals()[name] = value
    return value


def __dir__():
    return sorted(set(globals()) | set(_EXPORTS))


__version__ = "0.1.0"

__all__ = [
    "METHODS",
    "Branch",
    "Contract",
    "FlowMap",
    "FrequencyResponse",
    "InputError",
    "Modes",
    "Orbit",
    "PointResult",
    "RegimeMap",
    "ShootingError",
    "SimulationError",
    "StroboscopicMap",
    "SweepPoint",
    "SweepResult",
    "System",
    "Trajectory",
    "Units",
    "analyse",
    "continue_hb",
    "continue_orbit",
    "derive_model",
    "fit_dead_zone",
    "frequency_response",
    "harmonic_balance",
    "in_units",
    "load",
    "load_target",
    "modes",
    "orbit_in_units",
    "planetary",
    "plot",
    "regime_map",
    "reproduce",
    "save",
    "shoot",
    "simulate",
    "sweep",
    "switch_period_doubling",
]
