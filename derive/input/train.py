"""A gear train with closed loops as a topology file: bodies, meshes and shafts (issue 26).

A tree of meshes (``[[gear]]``, ``[[mesh]]``) is reduced to mesh coordinates; a train whose
meshes and shafts close a loop (a back-to-back "four-square" rig, a split-torque or idler
train) is not a tree and keeps each body's rotation as a coordinate.  Its file has a
``[train]`` table, in the same lumped terms as a planetary set's torsional model:

    [topology]
    name = "back-to-back-rig"
    [[train.body]]
    id = "pinion_test"
    inertia_kg_m2 = 2.5e-3
    base_radius_mm = 33.8                 # u = r theta; a body without teeth: any radius
    teeth = 16                            # a body in a mesh
    [[train.mesh]]
    id = "test"
    gears = ["pinion_test", "wheel_test"]
    internal = false                      # true: the second gear is a ring
    stiffness_N_per_m = 3.5e8             # mean, along the line of action
    half_backlash_um = 50
    variation = [[0.1, 0.0], [0.03, 0.0]] # optional: k(t) / k_m - 1, (cos, sin) per harmonic
    phase = 0.0                           # optional: in its own mesh periods
    transmission_error = { amplitude_um = [4.0], phase_deg = [0.0] }   # optional
    [[train.shaft]]
    id = "pinion_shaft"
    bodies = ["pinion_test", "pinion_slave"]
    torsional_Nm_per_rad = 2.0e4
    assembly_twist_deg = 1.0              # optional: the loading coupling's twist
    [[train.torque]]                      # optional: must leave the train's rotation unforced
    body = "wheel_test"
    torque_Nm = 0
    [train.dynamics]                      # the nonlinear model (modes need none)
    mesh_frequency_hz = 400               # of the first mesh: the operating point
    damping_ratio = 0.03

Every rotation is counted in one sense.  An external mesh's deflection along its line of
action adds its gears' ``u = r theta`` (``r`` the base radius), an internal one subtracts the
ring's; a shaft's twist is ``theta_a - theta_b``.  A shaft's ``assembly_twist_deg`` is the
twist it was assembled with (the loading coupling of a back-to-back rig clamped with its
halves turned apart), so it carries torque when the train is at rest: the locked-in load.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

from ..escape import is_target_name
from .planetary import topology_file
from .reader import InputError, Table, load_toml, nearest

__all__ = ["Body", "Link", "Train", "TrainDynamics", "is_train", "load_train"]


@dataclass(frozen=True)
class Body:
    id: str
    inertia: float  # kg m^2
    radius: float  # m: the unit of its coordinate u = r theta (a gear's base radius)
    teeth: int | None


@dataclass(frozen=True)
class Link:
    """A mesh (stiffness N/m along its line of action) or a shaft (N m/rad)."""

    id: str
    kind: str  # "mesh" or "shaft"
    bodies: tuple[str, str]
    stiffness: float
    internal: bool = False  # a mesh whose second gear is a ring
    half_backlash: float = 0.0  # m (a mesh)
    variation: tuple[tuple[float, float], ...] = ()  # (cos, sin) of each harmonic (a mesh)
    phase: float = 0.0  # mesh periods (a mesh)
    twist: float = 0.0  # rad, at assembly (a shaft)
    error: object = None  # TransmissionError (a mesh): e(t) = sum_h a_h cos(h w t + phase_h)


@dataclass(frozen=True)
class TrainDynamics:
    mesh_frequency_hz: float  # of the first mesh
    damping_ratio: float


@dataclass(frozen=True)
class Train:
    name: str
    description: str
    source: str
    bodies: tuple[Body, ...]
    meshes: tuple[Link, ...]
    shafts: tuple[Link, ...]
    torques: dict  # body id -> N m
    dynamics: TrainDynamics | None


def is_train(path: Path | str) -> bool:
    """Whether the TOML file at ``path`` is a gear train with closed loops (``[train]``)."""
    path = Path(path)
    if path.suffix != ".toml" or not path.is_file():
        return False
    try:
        return "train" in load_toml(path)
    except InputError:
        return False


def _pair(t: Table, key: str, known: dict) -> tuple[str, str]:
    value = t.raw(key)
    if not (isinstance(value, list) and len(value) == 2 and all(isinstance(v, str) for v in value)):
        raise t.error(key, f'must name two bodies, ["a", "b"], got {value!r}')
    for v in value:
        if v not in known:
            raise t.error(key, f"names unknown body {v!r}" + nearest(v, known))
    if value[0] == value[1]:
        raise t.error(key, f"names body {value[0]!r} twice; a link joins two bodies")
    return value[0], value[1]


def _variation(t: Table) -> tuple[tuple[float, float], ...]:
    value = t.raw("variation", [])
    ok = isinstance(value, list) and all(
        isinstance(v, list)
        and len(v) == 2
        and all(isinstance(x, int | float) and not isinstance(x, bool) for x in v)
        and all(math.isfinite(x) for x in v)
        for v in value
    )
    if not ok:
        raise t.error(
            "variation",
            "must be a list of [cos, sin] pairs, one per harmonic of the mesh frequency, of "
            f"k(t) / k_mean - 1, got {value!r}",
        )
    if sum(math.hypot(*v) for v in value) >= 1.0:
        raise t.error(
            "variation",
            "its harmonics' amplitudes add up to 1 or more, so the stiffness could reach zero "
            "or below; give smaller ones",
        )
    return tuple((float(a), float(b)) for a, b in value)


def _error(t: Table | None):
    """A mesh's transmission error as a tree's mesh states it (``derive/input/meshes.py``,
    imported here only when a mesh has one: loading a cached model stays light)."""
    if t is None:
        return None
    from .meshes import _transmission_error

    return _transmission_error(t)


def _id(t: Table) -> str:
    """A body's, mesh's or shaft's id: letters, digits, '-' and '_', starting with a letter
    (it is printed, labels figures and names columns)."""
    value = t.string("id")
    if not is_target_name(value):
        raise t.error(
            "id",
            f"{value!r} must start with a letter and use only letters, digits, '-' and '_'",
        )
    return value


def _unique(tables: list[Table], seen: set) -> None:
    for t in tables:
        name = _id(t)
        if name in seen:
            raise t.error("id", f"{name!r} is used twice; give each body, mesh and shaft an id")
        seen.add(name)


def load_train(path: Path | str) -> Train:
    """Read and check a gear train's file (module docstring)."""
    source = str(path)
    top, name, description = topology_file(path)
    tr = top.table("train")
    body_tables = tr.tables("body")
    seen: set = set()
    _unique(body_tables, seen)
    bodies = {}
    for t in body_tables:
        bid = _id(t)
        teeth = t.integer("teeth", None, low=1) if t.has("teeth") else None
        bodies[bid] = Body(
            bid,
            t.number("inertia_kg_m2", low=0.0, low_open=True),
            t.number("base_radius_mm", low=0.0, low_open=True) * 1e-3,
            teeth,
        )
        t.finish()
    meshes = []
    mesh_tables = tr.tables("mesh")
    _unique(mesh_tables, seen)
    for t in mesh_tables:
        pair = _pair(t, "gears", bodies)
        for b in pair:
            if bodies[b].teeth is None:
                raise t.error("gears", f"gear {b!r} has no teeth; give its body a teeth count")
        meshes.append(
            Link(
                _id(t),
                "mesh",
                pair,
                t.number("stiffness_N_per_m", low=0.0, low_open=True),
                internal=t.boolean("internal", False),
                half_backlash=t.number("half_backlash_um", low=0.0, low_open=True) * 1e-6,
                variation=_variation(t),
                phase=t.number("phase", 0.0, low=0.0, high=1.0, high_open=True),
                error=_error(t.table("transmission_error", None)),
            )
        )
        t.finish()
    shafts = []
    shaft_tables = tr.tables("shaft") if tr.has("shaft") else []
    _unique(shaft_tables, seen)
    for t in shaft_tables:
        shafts.append(
            Link(
                _id(t),
                "shaft",
                _pair(t, "bodies", bodies),
                t.number("torsional_Nm_per_rad", low=0.0, low_open=True),
                twist=math.radians(t.number("assembly_twist_deg", 0.0, low=-90.0, high=90.0)),
            )
        )
        t.finish()
    torques: dict = {}
    for t in tr.tables("torque") if tr.has("torque") else []:
        bid = t.string("body")
        if bid not in bodies:
            raise t.error("body", f"names unknown body {bid!r}" + nearest(bid, bodies))
        torques[bid] = torques.get(bid, 0.0) + t.number("torque_Nm")
        t.finish()
    dynamics = None
    d = tr.table("dynamics", None)
    if d is not None:
        dynamics = TrainDynamics(
            d.number("mesh_frequency_hz", low=0.0, low_open=True),
            d.number("damping_ratio", 0.03, low=0.0, high=1.0),
        )
        d.finish()
    tr.finish()
    top.finish()
    return Train(
        name,
        description,
        source,
        tuple(bodies.values()),
        tuple(meshes),
        tuple(shafts),
        torques,
        dynamics,
    )
