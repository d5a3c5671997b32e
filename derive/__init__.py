"""gearsym.derive -- from gear data and topology to the non-dimensional model (SI inside).

Public entry points: :func:`load_target` (scene or topology file), :func:`derive_model`
and :func:`fit_dead_zone`; ``gearsym.derive.build`` writes the generated code and the
audit pages.
"""

import importlib as _importlib

from ._version import __version__
from .input.reader import InputError

# The rest resolves on first use (PEP 562): SymPy and SciPy load only when a derivation
# (or the scene reader) is asked for.
_EXPORTS = {
    "DeadZone": "mesh.backlash",
    "LinearContact": "mesh.backlash",
    "PolynomialFit": "mesh.backlash",
    "SmoothDeadZone": "mesh.backlash",
    "dead_zone": "mesh.backlash",
    "fit_dead_zone": "mesh.backlash",
    "Model": "model",
    "derive_model": "model",
    "Features": "input.features",
    "Scene": "input.scene",
    "load_scene": "input.scene",
    "load_target": "input.scene",
    "resolve_target": "input.scene",
    "variant": "input.scene",
    "Topology": "input.topology",
    "load_topology": "input.topology",
}


def __getattr__(name: str):
    if name not in _EXPORTS:
        raise AttributeError(f"module 'gearsym.derive' has no attribute {name!r}")
    value = getattr(_importlib.import_module(f".{_EXPORTS[name]}", __name__), name)
    globals()[name] = value
    return value


def __dir__():
    return sorted(set(globals()) | set(_EXPORTS))


__all__ = [
    "__version__",
    "DeadZone",
    "Features",
    "InputError",
    "LinearContact",
    "Model",
    "PolynomialFit",
    "Scene",
    "SmoothDeadZone",
    "Topology",
    "dead_zone",
    "derive_model",
    "fit_dead_zone",
    "load_scene",
    "load_target",
    "load_topology",
    "resolve_target",
    "variant",
]
