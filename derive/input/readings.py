"""Readings of the loads: which input gears drive, which brake, which coordinates run backwards.

A topology may state the physically distinct ways its loads can be read, as ``[[reading]]``
tables, and a scene picks one (``load_reading`` in its ``[open]`` table).  The reference
study allows two (``../shared/SEED.md``, "What the study leaves open"):

* ``q-braking``: pinion q is driven by g and takes power out (its torque opposes its
  rotation); every mesh coordinate is measured forward (driver flank loaded = positive);
* ``both-driving``: both pinions drive g; the q-g coordinate is measured the other way
  (``reversed``: positive when the driven gear's flank is loaded, ``x' = -x``).

A reading sets, for the derivation, the sign ``s_i = +1 / -1`` of each mesh coordinate
(orientation) and the sign ``sigma_k = +1 / -1`` of each input gear's torque (driving /
braking).  Nothing else is typed: the incidence matrix becomes ``A'_ik = s_i A_ik``, so the
compliance ``W_ij = s_i s_j (C A I^-1 A^T C)_ij``, and with it ``kappa_ij`` and ``xi_ij``,
change sign for ``i != j`` when one of the two coordinates is reversed; the transmission
error enters coordinate ``i`` as ``s_i e_i``; and the static load of a coordinate whose
scene load is given as a size takes the sign of the load its input gear's torque puts on it,
``sign(d f_i / d T_k) * sigma_k``, read off the derivation's load term ``(C A' I^-1 T)_i``.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

from ..escape import markdown
from .reader import InputError, Table, nearest

__all__ = [
    "ORIENTATIONS",
    "Reading",
    "apply_reading",
    "load_signs",
    "parse_readings",
    "reading_section",
]

ORIENTATIONS = {"forward": 1, "reversed": -1}


@dataclass(frozen=True)
class Reading:
    """One reading of the loads (see module text)."""

    id: str
    description: str
    driving: tuple[str, ...]  # input gears whose torque drives them (sigma = +1)
    braking: tuple[str, ...]  # input gears whose torque opposes their rotation (sigma = -1)
    reversed: tuple[str, ...]  # meshes whose coordinate is measured from the driven gear

    def role(self, gear: str) -> int:
        """sigma of ``gear``: +1 driving, -1 braking, 0 not an input gear of this reading."""
        return 1 if gear in self.driving else -1 if gear in self.braking else 0


def parse_readings(top: Table, gear_ids: list[str], mesh_ids: list[str]) -> dict[str, Reading]:
    """The ``[[reading]]`` tables of a topology, checked against its gears and meshes."""
    if not top.has("reading"):
        return {}
    readings: dict[str, Reading] = {}
    for rt in top.tables("reading"):
        rid = rt.target_name("id")
        if rid in readings:
            raise rt.error("id", f"reading '{rid}' is defined twice")
        lists = {}
        for key, known, what in (
            ("driving", gear_ids, "gear"),
            ("braking", gear_ids, "gear"),
            ("reversed", mesh_ids, "mesh"),
        ):
            names = rt.raw(key, [])
            if not isinstance(names, list) or not all(isinstance(n, str) for n in names):
                raise rt.error(key, f"must be a list of {what} ids, got {names!r}")
            for n in names:
                if n not in known:
                    raise rt.error(
                        key,
                        f"names no {what} '{n}'{nearest(n, known)}; {what}s: {', '.join(known)}",
                    )
            lists[key] = tuple(names)
        both = set(lists["driving"]) & set(lists["braking"])
        if both:
            raise rt.error("braking", f"gear '{sorted(both)[0]}' cannot both drive and brake")
        readings[rid] = Reading(rid, rt.string("description", ""), **lists)
        rt.finish()
    return readings


def apply_reading(topology, reading_id: str, where: str):
    """``topology`` read as ``reading_id``: its meshes' orientations and its input gears'
    torque signs set by the reading (torque sizes kept)."""
    reading = topology.readings.get(reading_id)
    if reading is None:
        known = list(topology.readings)
        hint = f"; readings: {', '.join(known)}" if known else "; it states no [[reading]]"
        message = f"'{reading_id}' is not a reading of topology '{topology.name}'"
        raise InputError(where, "load_reading", message + nearest(reading_id, known) + hint)
    meshes = tuple(
        replace(m, orientation=-1 if m.id in reading.reversed else m.orientation)
        for m in topology.meshes
    )
    torques = {
        g: (abs(t) * reading.role(g) if reading.role(g) else t) for g, t in topology.torques.items()
    }
    return replace(topology, meshes=meshes, torques=torques)


def load_signs(nd, topology, reading_id: str, where: str) -> dict[str, tuple[str, int, int]]:
    """coordinate -> (input gear, sign of d f_i/d T_gear from the derivation, sigma of the
    gear); the load sign of the coordinate is the product of the last two."""
    reading = topology.readings[reading_id]
    out = {}
    for i, mesh in enumerate(topology.meshes):
        inputs = [g for g in (mesh.driver, mesh.driven) if reading.role(g)]
        if len(inputs) != 1:
            raise InputError(
                where,
                "load_reading",
                f"reading '{reading_id}' must name exactly "
                f"one input gear of mesh '{mesh.id}' in driving or braking, "
                f"names {len(inputs)}",
            )
        gear = inputs[0]
        slope = nd.value(nd.load[i].diff(nd.torque_symbol(gear)))
        out[mesh.coordinate] = (gear, 1 if slope > 0 else -1, reading.role(gear))
    return out


def reading_section(model) -> str:
    """The audit page's paragraph on the reading of the loads (empty without one)."""
    scene, topo = model.scene, model.scene.topology
    if scene.load_reading is None:
        return ""
    reading = topo.readings[scene.load_reading]
    nd = model.nondim
    lines = [
        f"## Reading of the loads: `{reading.id}`\n",
        (markdown(reading.description) + ". " if reading.description else "")
        + "The reading sets the orientation $s_i$ of each mesh coordinate and the sign "
        "$\\sigma_k$ of each input torque; the scene gives each load as a size, and its sign "
        "is that of $\\partial f_i/\\partial T_k$ (from the load term of section 8) times "
        "$\\sigma_k$. The coupling signs follow from $W_{ij} = s_i s_j (C A I^{-1} A^T C)_{ij}$"
        " (section 4). No sign is typed in.\n",
        "| coordinate | mesh | orientation $s_i$ | input gear | $\\sigma_k$ | "
        "sign of $\\partial f_i/\\partial T_k$ | size | $f_i$ |",
        "|---|---|---|---|---|---|---|---|",
    ]
    signs = load_signs(nd, topo, reading.id, scene.source)
    values = dict(zip(model.parameter_names, model.defaults, strict=True))
    for me in topo.meshes:
        c = me.coordinate
        gear, slope, sigma = signs[c]
        lines.append(
            f"| {c} | {me.id} | {'+1 forward' if me.orientation > 0 else '-1 reversed'} | "
            f"{gear} | {'+1 driving' if sigma > 0 else '-1 braking'} | {slope:+d} | "
            f"`{markdown(scene.load_expressions[c], code=True)}` | {values[f'f_{c}']:.6g} |"
        )
    coupling = [
        f"`{n}` = {values[n]:.6g}"
        for n in model.parameter_names
        if n.startswith(("kappa_", "xi_")) and n.split("_")[1] != n.split("_")[2]
    ]
    if coupling:
        lines.append("\nCoupling terms that result: " + ", ".join(coupling) + ".")
    return "\n".join(lines) + "\n"
