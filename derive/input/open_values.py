"""Open values: what the reference study leaves unstated, as keys a user sets.

Each key edits the topology's *input data* (the parsed TOML tables) before the topology is
built, so that everything derived from it follows through the ordinary derivation: a
flywheel inertia changes the inertia of its gear, hence the reduced masses, kappa_uv,
kappa_vu, xi_uv, xi_vu and omega_n together; a transmission-error amplitude in um becomes
E = amplitude / half backlash; a layout angle becomes the stiffness phase phi.  Keys:

========================================  ============================================
``te_amplitude_um`` / ``..._<mesh>``      first-harmonic transmission-error amplitude
                                          (um), every mesh / one mesh
``te_phase_deg`` / ``..._<mesh>``         its phase (deg)
``flywheel_inertia_kg_m2``                the attached inertia of the one gear that
                                          carries one (kg m^2)
``attached_inertia_kg_m2_<gear>``         the attached inertia of one gear (kg m^2)
``layout_angle_deg`` / ``..._<mesh>``     the angle round the shared gear between this
                                          mesh and the reference mesh (deg); every mesh
                                          that has one / one mesh
``stiffness_harmonic_scale`` /            factor on every stiffness harmonic k_j1, k_j2
``..._<mesh>``                            (the mean k_m kept)
``load_reading``                          a ``[[reading]]`` of the topology (text):
                                          ``q-braking`` or ``both-driving`` for the
                                          reference stage (``derive/input/readings.py``)
``damping_normalisation``                 ``mesh`` or ``modal`` (text,
                                          ``derive/equations/nondim.py``)
========================================  ============================================

A scene file sets them in an ``[open]`` table; ``gearsym.load(scene, **values)`` and the
CLI's ``--set`` accept them beside ordinary parameters and derive (once, into the
derivation cache) the model they give.  A value equal to the scene's own changes nothing
and derives nothing.  :func:`is_open_value` (or the frozenset :data:`OPEN_VALUE_BASES`
with the per-mesh/per-gear suffixes) tells a sweep or map whether a name needs a
derivation.
"""

from __future__ import annotations

import copy
import math
from dataclasses import replace

from .reader import InputError, nearest

__all__ = [
    "CHOICES",
    "OPEN_VALUES",
    "OPEN_VALUE_BASES",
    "apply_open_values",
    "is_open_value",
    "with_open_values",
]

# key -> (unit, meaning, low, high)
OPEN_VALUES = {
    "te_amplitude_um": ("um", "first-harmonic transmission-error amplitude", 0.0, 1e4),
    "te_phase_deg": ("deg", "first-harmonic transmission-error phase", -360.0, 360.0),
    "flywheel_inertia_kg_m2": ("kg m^2", "attached (flywheel) inertia", 0.0, 1e9),
    "attached_inertia_kg_m2": ("kg m^2", "attached inertia of a gear", 0.0, 1e9),
    "layout_angle_deg": ("deg", "angle between this mesh and the reference mesh", -360.0, 360.0),
    "stiffness_harmonic_scale": ("1", "factor on the stiffness harmonics", 0.0, 1e3),
}
_PER_MESH = ("te_amplitude_um", "te_phase_deg", "layout_angle_deg", "stiffness_harmonic_scale")
# key -> meaning; text values, which set the scene rather than the topology's data
CHOICES = {
    "load_reading": "the reading of the loads, a [[reading]] of the topology",
    "damping_normalisation": "how the damping ratio sets the dampers: mesh or modal",
}
# Every open-value name is one of these, or one of the per-mesh / per-gear ones
# (``<base>_<mesh id>``, ``attached_inertia_kg_m2_<gear id>``): use is_open_value().
OPEN_VALUE_BASES = frozenset(OPEN_VALUES) | frozenset(CHOICES)


def _split(name: str) -> tuple[str, str | None] | None:
    """(base key, mesh or gear id) of an open-value name, or None."""
    if name in OPEN_VALUES and name != "attached_inertia_kg_m2":
        return name, None
    for base in OPEN_VALUES:
        if name.startswith(base + "_") and len(name) > len(base) + 1:
            if base in _PER_MESH or base == "attached_inertia_kg_m2":
                return base, name[len(base) + 1 :]
    return None


def is_open_value(name: str) -> bool:
    """Whether ``name`` is an open value (a key that needs a new derivation)."""
    return name in CHOICES or _split(name) is not None


def apply_open_values(data: dict, values: dict, where: str) -> dict:
    """A copy of the topology's TOML ``data`` with ``values`` applied (see module text);
    a bad key or value raises :class:`InputError` naming it and the fix."""
    data = copy.deepcopy(data)
    meshes = data.get("mesh", [])
    gears = data.get("gear", [])
    mesh_ids = [m.get("id") for m in meshes]
    gear_ids = [g.get("id") for g in gears]
    for name, value in values.items():
        split = _split(name)
        if split is None:
            allowed = [*OPEN_VALUES, *CHOICES] + [f"{k}_{m}" for k in _PER_MESH for m in mesh_ids]
            raise InputError(
                where,
                name,
                "is not an open value"
                + nearest(name, allowed)
                + f"; open values: {', '.join([*OPEN_VALUES, *CHOICES])}",
            )
        base, which = split
        unit, meaning, low, high = OPEN_VALUES[base]
        try:
            value = float(value)
        except (TypeError, ValueError):
            raise InputError(where, name, f"must be a number ({unit}), got {value!r}") from None
        if not (math.isfinite(value) and low <= value <= high):
            raise InputError(where, name, f"must be in [{low:g}, {high:g}] {unit}, got {value:g}")
        if base in ("flywheel_inertia_kg_m2", "attached_inertia_kg_m2"):
            if which is None:
                carriers = [g for g in gears if g.get("attached_inertia_kg_m2", 0) > 0]
                if len(carriers) != 1:
                    raise InputError(
                        where,
                        name,
                        f"needs exactly one gear with an attached inertia, found "
                        f"{len(carriers)}; set attached_inertia_kg_m2_<gear> instead",
                    )
                targets = carriers
            else:
                if which not in gear_ids:
                    raise InputError(
                        where,
                        name,
                        f"names no gear{nearest(which, gear_ids)}; "
                        f"gears: {', '.join(map(str, gear_ids))}",
                    )
                targets = [gears[gear_ids.index(which)]]
            for g in targets:
                g["attached_inertia_kg_m2"] = value
            continue
        if which is not None and which not in mesh_ids:
            raise InputError(
                where,
                name,
                f"names no mesh{nearest(which, mesh_ids)}; meshes: {', '.join(map(str, mesh_ids))}",
            )
        chosen = meshes if which is None else [meshes[mesh_ids.index(which)]]
        if base == "layout_angle_deg":
            chosen = [m for m in chosen if "layout_angle_deg" in m] if which is None else chosen
            if not chosen:
                raise InputError(where, name, "no mesh of this topology has a layout angle")
            for m in chosen:
                m.pop("stiffness_phase_deg", None)
                m["layout_angle_deg"] = value
        elif base == "stiffness_harmonic_scale":
            for m in chosen:
                m["stiffness"] = dict(m.get("stiffness", {}), harmonic_scale=value)
        else:
            key = "amplitude_um" if base == "te_amplitude_um" else "phase_deg"
            for m in chosen:
                te = dict(m.get("transmission_error", {}))
                current = list(te.get(key, [])) or [0.0]
                current[0] = value
                te[key] = current
                if key == "phase_deg" and "amplitude_um" not in te:
                    te["amplitude_um"] = [0.0]
                if key == "amplitude_um" and "phase_deg" in te:
                    te["phase_deg"] = (list(te["phase_deg"]) + [0.0] * len(current))[: len(current)]
                m["transmission_error"] = te
    return data


def check_damping(value: str, where: str) -> None:
    """Raise :class:`InputError` unless ``value`` is a damping normalisation."""
    from ..equations.nondim import DAMPING_NORMALISATIONS

    if value not in DAMPING_NORMALISATIONS:
        known = DAMPING_NORMALISATIONS
        message = f"'{value}' is not one of {', '.join(known)}" + nearest(value, known)
        raise InputError(where, "damping_normalisation", message)


def with_open_values(scene, **values):
    """``scene`` with open values set: its topology rebuilt from the edited data (the
    scene's own ``[open]`` values kept beneath the new ones), the choices
    (``load_reading``, ``damping_normalisation``) applied, the values recorded (they enter
    the derivation's inputs hash) and the name suffixed with a short digest of them, so that
    a variant never passes for its original.  Values equal to the scene's own are dropped;
    with none left, ``scene`` itself is returned (nothing to derive)."""
    import hashlib
    import json

    from .reader import load_toml
    from .supports import load_topology_data
    from .topology import parse_topology

    where = f"{scene.source} (open values)"
    chosen = {k: v for k, v in values.items() if k in CHOICES}
    numbers = {k: v for k, v in values.items() if k not in CHOICES}
    for key, value in chosen.items():
        if not isinstance(value, str):
            raise InputError(where, key, f"must be text ({CHOICES[key]}), got {value!r}")
    own = {"load_reading": scene.load_reading, "damping_normalisation": scene.damping_normalisation}
    chosen = {k: v for k, v in chosen.items() if v != own[k]}
    source = scene.topology.source
    before = dict(scene.variations.get("open_values", {}))
    if scene.kind == "scene":
        opened = load_toml(scene.source).get("open", {})
        before = {k: v for k, v in opened.items() if k not in CHOICES} | before
    before = {k: v for k, v in before.items() if k not in CHOICES}
    data = load_topology_data(source)
    old = apply_open_values(data, before, where)
    new = apply_open_values(data, before | numbers, where)
    if new == old:
        numbers = {}
    numbers = {k: float(v) for k, v in numbers.items() if before.get(k) != float(v)}
    if not numbers and not chosen:
        return scene
    reading = chosen.get("load_reading", scene.load_reading)
    damping = chosen.get("damping_normalisation", scene.damping_normalisation)
    if "damping_normalisation" in chosen:
        check_damping(damping, where)
    topology = parse_topology(new, source)  # afresh: a reading replaced leaves no trace
    if reading is not None:
        from .readings import apply_reading

        topology = apply_reading(topology, reading, where)
    given = {k: v for k, v in sorted((before | numbers | chosen).items())}
    recorded = dict(scene.variations.get("open_values", {}))
    recorded = recorded | {k: float(v) for k, v in numbers.items()} | chosen
    tag = hashlib.sha256(json.dumps(given, sort_keys=True).encode()).hexdigest()[:8]
    base = scene.name.split("-open-")[0]
    return replace(
        scene,
        name=f"{base}-open-{tag}",
        topology=topology,
        variations=scene.variations | {"open_values": dict(sorted(recorded.items()))},
        load_reading=reading,
        damping_normalisation=damping,
    )
