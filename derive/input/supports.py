"""Bearings, shafts and topology files that extend another one (issue 15).

A ``[[bearing]]`` holds one gear to the housing: a spring and a viscous damper along each
transverse axis (``radial_N_per_m``, ``radial_damping_N_s_per_m``, the same along x and y
unless ``radial_y_N_per_m`` or ``radial_y_damping_N_s_per_m`` set y's: an anisotropic
support) and along the gear's axis (``axial_N_per_m``, ``axial_damping_N_s_per_m``).  A gear's
translations are modelled only when the scene asks for them (``degrees_of_freedom``); it
then needs a bearing, or it would float.

A ``[[shaft]]`` joins two gears that turn together (a multi-stage train's intermediate
shaft): a torsional spring ``torsional_Nm_per_rad`` and damper
``torsional_damping_Nm_s_per_rad`` between their rotations.  Meshes and shafts together
must form a tree over the gears.  A shaft carries no lateral coupling here: each gear sits
on its own bearing (the shaft's bending is lumped into the bearings' radial stiffness).

A topology file may start from another one: ``[topology] extends = "diso.toml"`` (a path
next to the file) takes that file's tables, then this file's on top: an entry of an array
of tables (``[[gear]]``, ``[[mesh]]``, ``[[shaft]]``, ``[[reading]]``) with an ``id``
already there, or a ``[[bearing]]`` of a gear that has one, updates that entry key by key;
any other entry is added, and plain tables merge key by key.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from .reader import InputError, Table, load_toml, nearest, not_a_table, shown

__all__ = ["Bearing", "Shaft", "load_topology_data", "parse_bearings", "parse_shafts"]


@dataclass(frozen=True)
class Bearing:
    """The support of one gear (SI units: N/m and N s/m)."""

    gear: str
    radial: float
    axial: float
    radial_damping: float = 0.0
    axial_damping: float = 0.0
    # Along y when it differs from x (an anisotropic support); None: the radial values.
    radial_y: float | None = None
    radial_y_damping: float | None = None
    # Tilting about the transverse axes (N m/rad, N m s/rad): needed by tilting models only.
    tilt: float | None = None
    tilt_damping: float = 0.0

    def transverse(self, axis: str) -> tuple[float, float, bool]:
        """(stiffness, damping, own) along ``x`` or ``y``: ``own`` when y has its own."""
        if axis == "y" and self.radial_y is not None:
            damping = (
                self.radial_damping if self.radial_y_damping is None else (self.radial_y_damping)
            )
            return self.radial_y, damping, True
        if axis == "y" and self.radial_y_damping is not None:
            return self.radial, self.radial_y_damping, True
        return self.radial, self.radial_damping, False


@dataclass(frozen=True)
class Shaft:
    """A torsional spring and damper joining the rotations of two gears (N m/rad, N m s/rad)."""

    id: str
    gears: tuple[str, str]
    stiffness: float
    damping: float = 0.0


def parse_bearings(top: Table, gears: dict) -> dict[str, Bearing]:
    """The ``[[bearing]]`` tables, by gear."""
    out: dict[str, Bearing] = {}
    for t in top.tables("bearing") if top.has("bearing") else []:
        gid = t.string("gear")
        if gid not in gears:
            raise t.error("gear", f"names unknown gear '{gid}'" + nearest(gid, gears))
        if gid in out:
            raise t.error("gear", f"gear '{gid}' has a bearing already; give one per gear")
        # Upper limit: far stiffer than any rolling or journal bearing (1e8-1e10 N/m); the
        # very-stiff limit a test needs stays inside it.
        out[gid] = Bearing(
            gid,
            t.number("radial_N_per_m", low=0, low_open=True, high=1e16),
            t.number("axial_N_per_m", low=0, low_open=True, high=1e16),
            t.number("radial_damping_N_s_per_m", 0.0, low=0.0, high=1e12),
            t.number("axial_damping_N_s_per_m", 0.0, low=0.0, high=1e12),
            t.number("radial_y_N_per_m", None, low=0, low_open=True, high=1e16),
            t.number("radial_y_damping_N_s_per_m", None, low=0.0, high=1e12),
            t.number("tilt_Nm_per_rad", None, low=0, low_open=True, high=1e16),
            t.number("tilt_damping_Nm_s_per_rad", 0.0, low=0.0, high=1e12),
        )
        t.finish()
    return out


def parse_shafts(top: Table, gears: dict) -> tuple[Shaft, ...]:
    """The ``[[shaft]]`` tables."""
    out: list[Shaft] = []
    for t in top.tables("shaft") if top.has("shaft") else []:
        sid = t.identifier("id")
        ends = t.raw("gears")
        if (
            not isinstance(ends, list)
            or len(ends) != 2
            or not all(isinstance(g, str) for g in ends)
        ):
            raise t.error("gears", f"must be a list of two gear ids, got {ends!r}")
        for gid in ends:
            if gid not in gears:
                raise t.error("gears", f"names unknown gear '{gid}'" + nearest(gid, gears))
        if ends[0] == ends[1]:
            raise t.error("gears", f"a shaft joins two different gears, got '{ends[0]}' twice")
        if any(s.id == sid for s in out):
            raise t.error("id", f"shaft '{sid}' is defined twice")
        out.append(
            Shaft(
                sid,
                (ends[0], ends[1]),
                t.number("torsional_Nm_per_rad", low=0, low_open=True, high=1e16),
                t.number("torsional_damping_Nm_s_per_rad", 0.0, low=0.0, high=1e12),
            )
        )
        t.finish()
    return tuple(out)


def load_topology_data(path: Path | str, _seen: tuple[str, ...] = ()) -> dict:
    """A topology file's tables with ``extends`` resolved (module docstring)."""
    path = Path(path)
    data = load_toml(path)
    _check_shape(data, _SHAPE, str(path), "")
    head = data.get("topology")
    if not isinstance(head, dict) or "extends" not in head:
        return data
    base_ref = head["extends"]
    if not isinstance(base_ref, str):
        raise InputError(str(path), "topology.extends", f"must be a file name, got {base_ref!r}")
    base_path = path.parent / base_ref
    if not base_path.exists():
        raise InputError(
            str(path), "topology.extends", f"'{base_ref}' is not a file next to {path.name}"
        )
    if str(base_path.resolve()) in _seen:
        raise InputError(str(path), "topology.extends", f"'{base_ref}' extends this file again")
    base = load_topology_data(base_path, (*_seen, str(path.resolve())))
    own = dict(data)
    own["topology"] = {k: v for k, v in head.items() if k != "extends"}
    return _merge(base, own)


# The shape of a topology file, checked as soon as it is read (open values edit the raw
# data before the topology is parsed): {key: shape} a table whose keys, where present, have
# these shapes ("*": every key); [shape] an array of such tables; "number", "numbers" and
# "text" plain values.  parse_topology checks everything else.
_SHAPE = {
    "topology": {},
    "materials": {"*": {}},
    "operating": {},
    "gear": [{"id": "text", "attached_inertia_kg_m2": "number"}],
    "mesh": [
        {
            "id": "text",
            "stiffness": {},
            "transmission_error": {"amplitude_um": "numbers", "phase_deg": "numbers"},
        }
    ],
    **{name: [{}] for name in ("torque", "bearing", "shaft", "reading")},
}


def _is_number(v) -> bool:
    return isinstance(v, int | float) and not isinstance(v, bool)


def _check_shape(value, shape, source: str, key: str) -> None:
    """Raise :class:`InputError` naming the first value of ``value`` not of ``shape``."""
    if isinstance(shape, list):
        if not isinstance(value, list):
            what = f"an array of tables (one [[{key}]] header per entry)"
            raise InputError(source, key, f"must be {what}, got {shown(value)}")
        for i, entry in enumerate(value):
            _check_shape(entry, shape[0], source, f"{key}[{i}]")
    elif isinstance(shape, dict):
        if not isinstance(value, dict):
            raise not_a_table(source, key, value)
        for k, v in value.items():
            if k in shape or "*" in shape:
                _check_shape(v, shape.get(k, shape.get("*")), source, f"{key}.{k}" if key else k)
    elif shape == "text" and not isinstance(value, str):
        raise InputError(source, key, f'must be text in quotes ("..."), got {shown(value)}')
    elif shape == "number" and not _is_number(value):
        raise InputError(source, key, f"must be a number, got {shown(value)}")
    elif shape == "numbers" and not (isinstance(value, list) and all(map(_is_number, value))):
        raise InputError(source, key, f"must be a list of numbers, got {shown(value)}")


_ENTRY_KEYS = {"bearing": "gear"}  # what names an entry of an array of tables (else "id")


def _merge(base: dict, top: dict) -> dict:
    out = dict(base)
    for key, value in top.items():
        old = out.get(key)
        if isinstance(old, dict) and isinstance(value, dict):
            out[key] = _merge(old, value)
        elif isinstance(old, list) and isinstance(value, list):
            merged = [dict(e) if isinstance(e, dict) else e for e in old]
            name = _ENTRY_KEYS.get(key, "id")
            for entry in value:
                same = [
                    k
                    for k, e in enumerate(merged)
                    if isinstance(e, dict)
                    and isinstance(entry, dict)
                    and name in entry
                    and e.get(name) == entry[name]
                ]
                if same:
                    merged[same[0]] = merged[same[0]] | entry
                else:
                    merged.append(entry)
            out[key] = merged
        else:
            out[key] = value
    return out
