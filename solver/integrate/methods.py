"""The integration methods, as data: one frozen record per name, one validated registry.

``simulate(method=...)`` looks its method up here; the record says which back end runs
it and what its options mean, so no caller keeps its own list of names.
"""

from __future__ import annotations

from dataclasses import dataclass

__all__ = ["METHODS", "RENAMED", "Method", "get_method", "method_names"]


@dataclass(frozen=True)
class Method:
    """One integration method.

    Attributes
    ----------
    name : str
        The name users pass (``simulate(method=name)``).
    family : {"scipy", "casadi", "native"}
        The back end that runs it.
    adaptive : bool
        Error-controlled step (``rtol``, ``atol``) or fixed step (``steps_per_period``).
    order : int
        Order of the underlying scheme (of the propagated solution for adaptive pairs).
    step_unit : int
        For fixed-step methods, steps per sample interval must be a multiple of this
        (a collocation element holds four points); 0 for adaptive methods.
    locates_surfaces : bool
        Stops and restarts at the switching surfaces of a piecewise model (the one event
        loop of ``solver/integrate/events.py``); the others rely on error control or a
        fine fixed step.
    description : str
    engine_name : str
        The name the back end knows it by (SciPy's ``solve_ivp(method=...)``), when it
        differs from ``name``; empty: the same.
    """

    name: str
    family: str
    adaptive: bool
    order: int
    step_unit: int = 0
    locates_surfaces: bool = False
    description: str = ""
    engine_name: str = ""

    @property
    def engine(self) -> str:
        """The name the back end is given."""
        return self.engine_name or self.name

    def __post_init__(self):
        if self.family not in ("scipy", "casadi", "native"):
            raise ValueError(f"method {self.name}: unknown family {self.family!r}")
        if self.adaptive == bool(self.step_unit):
            raise ValueError(f"method {self.name}: a step unit goes with fixed-step methods only")
        if self.order < 1:
            raise ValueError(f"method {self.name}: order must be >= 1")


_RECORDS = (
    Method(
        "RK45",
        "scipy",
        True,
        5,
        locates_surfaces=True,
        description="SciPy Dormand-Prince 5(4): the reference study's method",
    ),
    Method(
        "scipy-dop853",
        "scipy",
        True,
        8,
        locates_surfaces=True,
        description="SciPy Dormand-Prince 8(5,3)",
        engine_name="DOP853",
    ),
    Method(
        "LSODA",
        "scipy",
        True,
        12,
        locates_surfaces=True,
        description="SciPy LSODA (Adams / BDF switching), with the generated Jacobian",
    ),
    Method(
        "Radau",
        "scipy",
        True,
        5,
        locates_surfaces=True,
        description="SciPy implicit Radau IIA, with the generated Jacobian",
    ),
    Method(
        "cvodes",
        "casadi",
        True,
        5,
        description="CasADi CVODES (SUNDIALS, variable-order BDF/Adams)",
    ),
    Method(
        "rk",
        "casadi",
        False,
        4,
        step_unit=1,
        description="CasADi fixed-step RK4, steps_per_period steps",
    ),
    Method(
        "collocation",
        "casadi",
        False,
        7,
        step_unit=4,
        description="CasADi fixed-step Radau IIA collocation, elements of four points",
    ),
    Method(
        "dop853",
        "native",
        True,
        8,
        description="compiled DOP853 on the generated C right-hand side",
    ),
    Method(
        "dopri5",
        "native",
        True,
        5,
        description="compiled Dormand-Prince 5(4) on the generated C right-hand side",
    ),
    Method("rk4", "native", False, 4, step_unit=1, description="compiled fixed-step classic RK4"),
)

REGISTRY: dict[str, Method] = {m.name: m for m in _RECORDS}
METHODS: tuple[str, ...] = tuple(REGISTRY)

# Old names, refused with the new one: "DOP853" and the compiled "dop853" differed by case
# only (issue 25).
RENAMED: dict[str, str] = {
    "DOP853": "method 'DOP853' is now 'scipy-dop853' (the SciPy integrator; 'dop853' is the "
    "compiled one)",
}


def method_names(family: str | None = None) -> tuple[str, ...]:
    return tuple(m.name for m in _RECORDS if family is None or m.family == family)


def get_method(name: str) -> Method:
    """The record of ``name``; an unknown name fails listing the valid ones, and an old
    name (:data:`RENAMED`) fails naming the new one."""
    if isinstance(name, str) and name in RENAMED:
        raise ValueError(RENAMED[name])
    try:
        return REGISTRY[name]
    except (KeyError, TypeError):
        raise ValueError(f"unknown method '{name}'; methods: {', '.join(METHODS)}") from None
