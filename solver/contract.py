"""What the solver knows about a model: the generated module's ``CONTRACT``, checked.

A generated module states as data everything the solver needs (``derive/model.py`` builds
it, ``derive/emit/python.py`` prints it): the state and parameter order, where each coordinate's
velocity is, which parameter sets the excitation period, which parameters are static
loads, the contact edges of each mesh coordinate, where each mesh's force is zero and its
sign elsewhere (format 2), the switching surfaces (kinks) of a piecewise force law and the
range where the force law is valid.  The solver reads only this; it never parses
generated source or guesses from names.

Formats read: 1 (before ``force_sign``: its ``contact`` edges were stated as the dead
zone's, force zero between them, so that is how a format-1 contract is read) and 2.
"""

from __future__ import annotations

import hashlib
import importlib
import weakref
from dataclasses import dataclass, field
from pathlib import Path
from types import ModuleType

import numpy as np

__all__ = ["CONTRACT_FORMAT", "READ_FORMATS", "Contract", "ForceSign", "load_generated"]

# The format this solver's derivations write (and the derivation cache's file names carry);
# it reads every format in READ_FORMATS.
CONTRACT_FORMAT = 2
READ_FORMATS = (1, 2)


@dataclass(frozen=True)
class ForceSign:
    """Where a mesh's backlash force ``g(u)`` is zero and its sign elsewhere.

    Attributes
    ----------
    zeros : tuple of float
        Sorted, distinct ``u`` (half backlashes) with ``g(u) = 0``.
    signs : tuple of int
        Sign (-1, 0, 1) of ``g`` on ``(-inf, zeros[0]), ..., (zeros[-1], inf)``.
    """

    zeros: tuple[float, ...]
    signs: tuple[int, ...]

    @classmethod
    def dead_zone(cls, lower: float, upper: float) -> ForceSign:
        """Zero on ``[lower, upper]``, the sign of ``u`` outside (format 1's reading)."""
        return cls((lower,), (-1, 1)) if lower == upper else cls((lower, upper), (-1, 0, 1))

    @property
    def edges(self) -> tuple[float, float]:
        """The outer zeros ``(lower, upper)``: ``g > 0`` beyond ``upper``, ``< 0`` below."""
        return (self.zeros[0], self.zeros[-1])

    @property
    def zero_between(self) -> bool:
        """``g`` vanishes on all of ``[lower, upper]`` (the teeth apart there)."""
        return len(self.zeros) > 1 and all(s == 0 for s in self.signs[1:-1])

    def sign(self, u) -> np.ndarray:
        """``sign(g(u))`` elementwise (int8, same shape as ``u``); 0 at each zero."""
        u = np.asarray(u, dtype=float)
        z = np.asarray(self.zeros)
        k = np.searchsorted(z, u, side="left")  # z[k-1] < u <= z[k]
        at_zero = (k < z.size) & (z[np.minimum(k, z.size - 1)] == u)
        return np.where(at_zero, 0, np.asarray(self.signs, dtype=np.int8)[k]).astype(np.int8)

    def problems(self) -> list[str]:
        """What is inconsistent in the table (empty when it is sound)."""
        out = []
        if not self.zeros or list(self.zeros) != sorted(set(self.zeros)):
            out.append("force zeros that are not sorted and distinct")
        if len(self.signs) != len(self.zeros) + 1 or not set(self.signs) <= {-1, 0, 1}:
            out.append("not one sign (-1, 0, 1) per interval between the force zeros")
        return out


_REQUIRED = ("NAME", "CONTRACT", "parameters", "rhs", "jacobian", "casadi_functions")
# module -> (its CONTRACT object, the Contract read from it): Contract.of
_READ: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


@dataclass(frozen=True)
class Contract:
    """A model's contract (see the module docstring); immutable.

    Attributes
    ----------
    states, coordinates, parameters : tuple of str
        State order, mesh coordinates (a subset of the states), parameter order.
    velocities : dict
        coordinate -> index of its time derivative in the state vector.
    forcing_frequency : str
        The parameter omega whose value gives the excitation period 2 pi / omega.
    loads : dict
        coordinate -> name of its static-load parameter (coordinates without one absent).
    contact : dict
        coordinate -> (lower, upper) edges of the backlash gap, in coordinate units (the
        geometry; where the force is zero is ``force_sign``).
    piecewise : bool
        The right-hand side has kinks (``switching_surfaces``) that integrators locate.
    switching_surfaces : tuple of (int, float)
        ``(i, c)``: the kink ``x[i] = c``.
    switching_rows : tuple of (tuple of float, float)
        ``(a, c)``: a kink on ``a . x = c`` that is not a coordinate's (a mesh of a
        planetary set, whose deflection is a sum of body coordinates); integrators do not
        locate these, their adaptive steps resolve them.
    valid_range : dict or None
        coordinate -> bound ``a``: the force law holds for ``|x| <= a`` only.
    functions : tuple of str
        The functions the module defines for a solver (``rhs``, ``jacobian``, ...,
        ``mesh_force``, ``static_mesh_force``); each is checked to be there.
    force_sign : dict
        coordinate -> :class:`ForceSign` of its backlash force; a format-1 contract, or a
        contract built without it, reads its ``contact`` edges as a dead zone.
    """

    states: tuple[str, ...]
    coordinates: tuple[str, ...]
    parameters: tuple[str, ...]
    velocities: dict
    forcing_frequency: str
    loads: dict
    contact: dict
    piecewise: bool
    switching_surfaces: tuple
    valid_range: dict | None
    functions: tuple[str, ...] = ("parameters", "rhs", "jacobian", "casadi_functions")
    force_sign: dict = field(default_factory=dict)
    switching_rows: tuple = ()

    def __post_init__(self):
        if not self.force_sign:
            dead = {c: ForceSign.dead_zone(lo, hi) for c, (lo, hi) in self.contact.items()}
            object.__setattr__(self, "force_sign", dead)

    @classmethod
    def of(cls, module: ModuleType) -> Contract:
        """The checked contract of a generated module (``ValueError`` names what is wrong),
        read once per module and CONTRACT object (a sweep point asks for it some fourteen
        times, a third of a millisecond each; a module given another CONTRACT is read
        again, and a CONTRACT is never changed in place)."""
        try:
            stated, known = _READ[module]
        except (KeyError, TypeError):
            stated = known = None
        if known is not None and stated is module.CONTRACT:
            return known
        c = cls._read(module)
        try:
            _READ[module] = (module.CONTRACT, c)
        except TypeError:  # an object that cannot be weakly referred to: read each time
            pass
        return c

    @classmethod
    def _read(cls, module: ModuleType) -> Contract:
        data = dict(module.CONTRACT)
        name = getattr(module, "NAME", module.__name__)
        fmt = data.get("format")
        if fmt not in READ_FORMATS:
            raise ValueError(
                f"model '{name}' states contract format {fmt!r}, this solver reads formats "
                f"{', '.join(map(str, READ_FORMATS))}; regenerate it with `gearsym derive`"
            )
        fields = (
            "states",
            "coordinates",
            "parameters",
            "velocities",
            "forcing_frequency",
            "loads",
            "contact",
            "piecewise",
            "switching_surfaces",
            "valid_range",
            *(("force_sign",) if fmt >= 2 else ()),
        )
        missing = [k for k in fields if k not in data]
        if missing:
            raise ValueError(f"model '{name}': CONTRACT lacks {', '.join(missing)}")
        c = cls(
            states=tuple(data["states"]),
            coordinates=tuple(data["coordinates"]),
            parameters=tuple(data["parameters"]),
            velocities=dict(data["velocities"]),
            forcing_frequency=str(data["forcing_frequency"]),
            loads=dict(data["loads"]),
            contact={k: (float(a), float(b)) for k, (a, b) in dict(data["contact"]).items()},
            piecewise=bool(data["piecewise"]),
            switching_surfaces=tuple((int(i), float(v)) for i, v in data["switching_surfaces"]),
            valid_range=None
            if data["valid_range"] is None
            else {k: float(v) for k, v in dict(data["valid_range"]).items()},
            functions=tuple(str(f) for f in data.get("functions", cls.functions)),
            force_sign=_force_signs(data.get("force_sign", {}), name),
            switching_rows=tuple(
                (tuple(float(a) for a in row), float(v))
                for row, v in data.get("switching_rows", ())
            ),
        )
        c._check(name)
        absent = [f for f in c.functions if not callable(getattr(module, f, None))]
        if absent:
            raise ValueError(
                f"model '{name}': CONTRACT lists {', '.join(absent)}, which the module does "
                "not define; regenerate it with `gearsym derive`"
            )
        return c

    def _check(self, name: str) -> None:
        problems = []
        n = len(self.states)
        if not set(self.coordinates) <= set(self.states):
            problems.append("coordinates that are not states")
        if set(self.velocities) != set(self.coordinates):
            problems.append("velocities not given for exactly the coordinates")
        if any(not 0 <= i < n for i in self.velocities.values()):
            problems.append("a velocity index outside the state")
        if len(set(self.velocities.values())) != len(self.velocities):
            problems.append("two coordinates share a velocity")
        coords = set(self.coordinates)
        tables = {"loads": self.loads, "contact": self.contact, "valid": self.valid_range or {}}
        for key, table in tables.items():
            if not set(table) <= coords:
                problems.append(f"{key} names something that is not a coordinate")
        if any(not lower <= upper for lower, upper in self.contact.values()):
            problems.append("contact edges with lower > upper")
        if not set(self.force_sign) <= coords:
            problems.append("force_sign names something that is not a coordinate")
        for coord, sign in self.force_sign.items():
            problems.extend(f"{coord}: {p}" for p in sign.problems())
        if any(not a > 0 for a in (self.valid_range or {}).values()):
            problems.append("a valid range that is not > 0")
        if self.forcing_frequency not in self.parameters:
            problems.append(f"forcing frequency '{self.forcing_frequency}' is not a parameter")
        if any(p not in self.parameters for p in self.loads.values()):
            problems.append("a load that is not a parameter")
        if any(not 0 <= i < n for i, _ in self.switching_surfaces):
            problems.append("a switching surface outside the state")
        if self.piecewise != bool(self.switching_surfaces or self.switching_rows):
            problems.append("piecewise must go with switching surfaces and smooth with none")
        if any(len(row) != n for row, _ in self.switching_rows):
            problems.append("a switching row that is not one coefficient per state")
        if problems:
            raise ValueError(f"model '{name}': inconsistent CONTRACT ({'; '.join(problems)})")

    # -- questions the solver asks ----------------------------------------------------
    def provides(self, *functions: str) -> bool:
        """True when the module defines every one of ``functions`` (its contract says so)."""
        return all(f in self.functions for f in functions)

    def index(self, state: str) -> int:
        try:
            return self.states.index(state)
        except ValueError:
            raise KeyError(f"no state '{state}'; states: {', '.join(self.states)}") from None

    def coordinate_indices(self) -> list[int]:
        return [self.states.index(c) for c in self.coordinates]

    def velocity(self, coordinate: str) -> int:
        """Index of the time derivative of ``coordinate``."""
        return self.velocities[coordinate]

    def velocity_of_state(self, i: int) -> int | None:
        """Index of the time derivative of state ``i`` when it is a coordinate, else None."""
        name = self.states[i]
        return self.velocities.get(name)

    def valid_bounds(self) -> list[tuple[int, float]]:
        """``(state index, bound)`` for each coordinate with a valid range."""
        if self.valid_range is None:
            return []
        return [(self.states.index(c), a) for c, a in self.valid_range.items()]


def _force_signs(table: dict, name: str) -> dict:
    """The contract's ``force_sign`` entries as :class:`ForceSign`, each checked against
    the outer zeros and the flag it states beside its table."""
    out = {}
    keys = ("edges", "zero_between", "zeros", "signs")
    for coord, entry in dict(table).items():
        lacks = [k for k in keys if k not in entry]
        if lacks:
            raise ValueError(
                f"model '{name}': CONTRACT force_sign of {coord} lacks {', '.join(lacks)}; "
                "regenerate it with `gearsym derive`"
            )
        sign = ForceSign(
            tuple(float(z) for z in entry["zeros"]), tuple(int(s) for s in entry["signs"])
        )
        stated = (tuple(float(e) for e in entry["edges"]), bool(entry["zero_between"]))
        if not sign.problems() and stated != (sign.edges, sign.zero_between):
            raise ValueError(
                f"model '{name}': CONTRACT force_sign of {coord} states edges and flag "
                f"{stated}, its zeros and signs give {(sign.edges, sign.zero_between)}; "
                "regenerate it with `gearsym derive`"
            )
        out[coord] = sign
    return out


# Modules run from a file, by (path, sha256 of the bytes run): a worker that meets the same
# verified bytes again (a map's next column) takes the module it made, not a new one.
_LOADED: dict[tuple[str, str], ModuleType] = {}


def load_generated(name_or_path: str | Path, source: bytes | None = None) -> ModuleType:
    """Import ``generated/<name>.py`` by model name, or a generated file by path.

    A file is run from the bytes read here (``source``: bytes already read and verified
    by the caller), never from a ``__pycache__`` copy that nobody checked; when a digest
    file ``<name>.sha256`` stands beside it (the derivation cache writes one), the bytes
    must hash to it, so a worker process that loads a cached model by path verifies it
    too."""
    path = Path(name_or_path)
    if path.suffix == ".py":
        try:
            data = path.read_bytes() if source is None else source
        except FileNotFoundError:
            raise FileNotFoundError(f"{path}: no such generated model file") from None
        stated = path.with_suffix(".sha256")
        if source is None and stated.exists():
            digest = stated.read_text(encoding="ascii", errors="replace").strip()
            if hashlib.sha256(data).hexdigest() != digest:
                raise ValueError(
                    f"{path} does not match the digest beside it ({stated.name}); derive "
                    "it again (`gearsym derive` on its scene)"
                )
        key = (str(path.resolve()), hashlib.sha256(data).hexdigest())
        module = _LOADED.get(key)
        if module is None:
            module = ModuleType(f"gearsym_generated_{path.stem}")
            module.__file__ = str(path)
            exec(compile(data, str(path), "exec", dont_inherit=True), module.__dict__)
            if not [k for k in _REQUIRED if not hasattr(module, k)]:
                _LOADED[key] = module
    else:
        try:
            # Built-in names may be written with hyphens, as the scene files are.
            name = str(name_or_path).replace("-", "_")
            module = importlib.import_module(f"gearsym.generated.{name}")
        except ModuleNotFoundError:
            raise FileNotFoundError(
                f"no generated model '{name_or_path}'; run `gearsym derive` on its scene"
            ) from None
    missing = [k for k in _REQUIRED if not hasattr(module, k)]
    if missing:
        raise ValueError(
            f"{module.__name__} is not a gearsym model of this version (lacks "
            f"{', '.join(missing)}); regenerate it with `gearsym derive`"
        )
    return module
