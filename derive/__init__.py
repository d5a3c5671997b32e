"""gearsym.derive -- from gear data and topology to the non-dimensional model (SI inside).

Public entry points: :func:`load_target` (scene or topology file), :func:`derive_model`
and :func:`fit_dead_zone`; ``gearsym.derive.build`` writes the generated code and the
audit pages.
"""

from ._input import InputError
from ._version import __version__
from .backlash import (
    DeadZone,
    LinearContact,
    PolynomialFit,
    SmoothDeadZone,
    dead_zone,
    fit_dead_zone,
)
from .model import Model, derive_model
from .scene import Features, Scene, load_scene, load_target, resolve_target, variant
from .topology import Topology, load_topology

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
