"""A generated model, ready to integrate: names, parameter vector, period, CasADi graphs.

:class:`System` is the solver's only view of a model.  It reads the generated module's
interface (``STATES``, ``PARAMETERS``, ``parameters()``, ``rhs``, ``jacobian``,
``casadi_functions``) and never anything about gears.  It is immutable; ``with_values``
returns a new system with other parameter values, sharing the compiled CasADi graphs.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from functools import cached_property
from types import ModuleType

import numpy as np

from ._models import load_generated

__all__ = ["System"]


@dataclass(frozen=True, eq=False)
class System:
    """A generated model with one set of parameter values.

    Attributes
    ----------
    module : module
        The generated module.
    p : ndarray, shape (P,)
        Parameter vector in the module's order.
    values : dict
        The named values (scene or model parameters) that produced ``p``.
    """

    module: ModuleType
    p: np.ndarray
    values: dict = field(default_factory=dict)

    def __post_init__(self):
        bad = [n for n, v in zip(self.module.PARAMETERS, self.p, strict=True) if not np.isfinite(v)]
        if bad:
            raise ValueError(f"parameter(s) {', '.join(bad)} are not finite numbers")
        if not self.p[list(self.module.PARAMETERS).index("omega")] > 0:
            raise ValueError("omega (the excitation frequency) must be > 0")

    @classmethod
    def load(cls, name_or_module, **values) -> System:
        module = (
            name_or_module
            if isinstance(name_or_module, ModuleType)
            else load_generated(name_or_module)
        )
        return cls(module, module.parameters(**values), dict(values))

    def with_values(self, **values) -> System:
        """The same model with some named values changed (the rest kept)."""
        merged = self.values | values
        new = System(self.module, self.module.parameters(**merged), merged)
        # Share the CasADi graphs: they depend on the model, not on the values.
        for key in ("casadi",):
            if key in self.__dict__:
                new.__dict__[key] = self.__dict__[key]
        return new

    # -- names -------------------------------------------------------------------------
    @property
    def name(self) -> str:
        return self.module.NAME

    @property
    def states(self) -> tuple[str, ...]:
        return tuple(self.module.STATES)

    @property
    def coordinates(self) -> tuple[str, ...]:
        return tuple(self.module.COORDINATES)

    @property
    def n(self) -> int:
        return len(self.module.STATES)

    def index(self, state: str) -> int:
        try:
            return self.states.index(state)
        except ValueError:
            raise KeyError(f"no state '{state}'; states: {', '.join(self.states)}") from None

    def parameter(self, name: str) -> float:
        return float(self.p[list(self.module.PARAMETERS).index(name)])

    # -- forcing -----------------------------------------------------------------------
    @property
    def omega(self) -> float:
        """Excitation frequency (non-dimensional) of the reference mesh."""
        return self.parameter("omega")

    @property
    def period(self) -> float:
        """Forcing period T = 2 pi / omega (non-dimensional time)."""
        return 2.0 * math.pi / self.omega

    @property
    def valid_range(self) -> float | None:
        return self.module.VALID_RANGE

    @property
    def backlash(self) -> str:
        return self.module.FEATURES["backlash"]

    @property
    def model_hash(self) -> str:
        return self.module.INPUTS_SHA256

    # -- evaluation ----------------------------------------------------------------------
    def rhs(self, tau: float, x: np.ndarray) -> np.ndarray:
        return self.module.rhs(tau, x, self.p)

    def jacobian(self, tau: float, x: np.ndarray) -> np.ndarray:
        return self.module.jacobian(tau, x, self.p)

    @cached_property
    def casadi(self):
        """(rhs, jacobian) as CasADi Functions of (tau, x, p); built once per model."""
        return self.module.casadi_functions()

    def describe(self) -> dict:
        return {
            "model": self.name,
            "model_hash": self.model_hash,
            "values": {k: float(v) for k, v in self.values.items()},
            "parameters": dict(zip(self.module.PARAMETERS, map(float, self.p), strict=True)),
            "omega_n_rad_per_s": self.module.OMEGA_N,
            "half_backlash_m": dict(self.module.HALF_BACKLASH),
            "features": dict(self.module.FEATURES),
        }
