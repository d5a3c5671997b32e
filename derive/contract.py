"""The model's contract: what a solver needs to know about a derived model, as data.

Every generated module carries it as ``CONTRACT`` (``emit.py``); the solver reads only this
(``solver/contract.py`` checks it) and never parses generated source or guesses from
names.
"""

from __future__ import annotations

import sympy as sp

from .mesh.backlash import DEAD_ZONE_EDGES

__all__ = ["CONTRACT_FORMAT", "FUNCTIONS", "model_contract"]

# Version of the contract's layout; a solver refuses a format it does not read.
# 2: ``force_sign`` (where each mesh's force is zero and its sign elsewhere).
CONTRACT_FORMAT = 2
# What every emitted module defines (``emit/python.py``): the parameter vector, the
# right-hand side and its Jacobian, the CasADi builders, each mesh's dynamic and static force.
FUNCTIONS = (
    "parameters",
    "rhs",
    "jacobian",
    "casadi_functions",
    "mesh_force",
    "static_mesh_force",
)


def model_contract(model) -> dict:
    """What a solver needs to know about ``model``, as plain Python literals (a new
    dict on each call, so a caller's edits cannot leak into the model).

    ``format``
        :data:`CONTRACT_FORMAT`.
    ``states``, ``coordinates``, ``parameters``
        State order, the mesh coordinates (in half backlashes), parameter order of ``p``.
    ``velocities``
        coordinate -> index in the state vector of its time derivative, read off the
        first-order equations (the right-hand side of a coordinate is a state).
    ``forcing_frequency``
        The parameter ``omega``; the excitation period is ``2 pi / omega``.
    ``loads``
        coordinate -> its static-load parameter (coordinates that have one).
    ``contact``
        coordinate -> ``(lower, upper)`` edges of the backlash gap, ``(-1.0, 1.0)`` in half
        backlashes: the geometry (where the flanks are), whatever the force law.
    ``force_sign``
        coordinate -> the sign of its backlash force ``g(u)``
        (:class:`~.mesh.force_sign.ForceSign`): ``edges`` ``(lower, upper)``, the outer
        zeros of ``g`` (forward contact, ``g > 0``, for ``u > upper``; backward, ``g < 0``,
        for ``u < lower``); ``zero_between``, True when ``g`` vanishes on all of
        ``[lower, upper]`` (the teeth apart: a dead zone), False when it only crosses zero
        there (the polynomial fit: zeros at ``0, +-0.7701``, loaded inside the gap);
        ``zeros``, every zero of ``g`` in the valid range, sorted; ``signs``, the sign of
        ``g`` on each interval between them (``len(zeros) + 1`` entries).
    ``piecewise``
        True when the right-hand side contains a ``Piecewise`` (it has kinks).
    ``switching_surfaces``
        ``(state index i, value c)`` for each kink ``x[i] = c`` of the right-hand side:
        per coordinate in coordinate order, its backlash model's kinks (upper edge,
        then lower); ``()`` when smooth.
    ``valid_range``
        coordinate -> bound ``a``, the force law holding for ``|u| <= a`` only (a
        polynomial fit of the dead zone); None when valid everywhere.
    ``functions``
        The functions the module defines for a solver (:data:`FUNCTIONS`): a solver asks
        this, not the module's attributes, whether it may compute mesh forces.
    """
    index = {s: k for k, s in enumerate(model.state_symbols)}
    velocities = {}
    for c in model.coordinates:
        rate = model.rhs[model.states.index(c)]
        if rate not in index:
            raise AssertionError(f"the right-hand side of {c} is not a state: {rate}")
        velocities[c] = index[rate]
    pieces = {p for e in model.rhs for p in e.atoms(sp.Piecewise)}
    kinked = {s for p in pieces for s in p.free_symbols}
    backlash = model.features.backlash
    surfaces = tuple(
        (model.states.index(c), float(edge))
        for c in model.coordinates
        if model.state_symbols[model.states.index(c)] in kinked
        for edge in backlash.kinks
    )
    if bool(pieces) != bool(surfaces):
        raise AssertionError(
            f"backlash '{backlash.kind}' lists kinks {backlash.kinks} but the right-hand "
            f"side {'has' if pieces else 'has no'} Piecewise"
        )
    names = model.parameter_names
    valid = backlash.valid_range
    sign = backlash.force_sign().to_contract()
    return {
        "format": CONTRACT_FORMAT,
        "states": tuple(model.states),
        "coordinates": tuple(model.coordinates),
        "velocities": velocities,
        "parameters": tuple(names),
        "forcing_frequency": model.forcing_frequency,
        "loads": {c: f for c, f in model.load_parameters.items() if f in names},
        "contact": {c: tuple(float(e) for e in DEAD_ZONE_EDGES) for c in model.coordinates},
        "force_sign": {c: dict(sign) for c in model.coordinates},
        "piecewise": bool(pieces),
        "switching_surfaces": surfaces,
        "valid_range": None if valid is None else {c: float(valid) for c in model.coordinates},
        "functions": FUNCTIONS,
    }
