"""Gear-train topology as data: gears, meshes, external torques, operating point.

A topology file is TOML with unit-suffixed keys (``_mm``, ``_deg``, ``_um``, ``_Nm``,
``_kg_m2``, ``_N_per_m``, ``_Pa``, ``_kg_m3``, ``_rpm``); everything is converted to SI
(m, rad, N, kg, s) on load and validated.  See ``docs/user-guide.md`` for the full list
of keys.  Each rotating body is one gear; inertia attached to a gear (a flywheel, a
coupling) is lumped with it.  Every rotation and torque is counted positive in the
gear's own operating direction: a driving torque is positive, a load torque negative.
The meshes must form a tree over the gears (every gear reachable, no closed loop), so
that the ``m`` mesh coordinates and one rigid-body rotation describe the ``m + 1`` gears
exactly.

The gears are read by ``derive/input/gears.py``, the meshes by ``derive/input/meshes.py``;
this module holds the :class:`Topology` record and the checks of the whole train.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from fractions import Fraction
from pathlib import Path

from .gears import STEEL, Gear, Material, parse_gear, parse_material
from .meshes import Mesh, TransmissionError, parse_mesh
from .reader import InputError, Table, nearest
from .readings import parse_readings
from .supports import Bearing, Shaft, load_topology_data, parse_bearings, parse_shafts

# Gear, Material, Mesh and TransmissionError are re-exported: the records of a topology.
__all__ = [
    "Gear",
    "Material",
    "Mesh",
    "Operating",
    "Topology",
    "TransmissionError",
    "load_topology",
    "parse_topology",
]


@dataclass(frozen=True)
class Operating:
    """The operating point: the gear whose speed is given, that speed (rad/s) and the
    damping ratio of the meshes."""

    gear: str
    speed: float  # rad/s
    damping_ratio: float


@dataclass(frozen=True)
class Topology:
    """A checked gear train in SI units: gears, meshes (a tree over the gears, with any
    shafts), external torques (N m, by gear id), the operating point, the load readings and
    the bearings."""

    name: str
    description: str
    gears: tuple[Gear, ...]
    meshes: tuple[Mesh, ...]
    torques: dict[str, float] = field(default_factory=dict)  # N m, on gears
    operating: Operating | None = None
    source: str = ""
    readings: dict = field(default_factory=dict)  # id -> derive.readings.Reading
    bearings: dict[str, Bearing] = field(default_factory=dict)  # gear id -> its bearing
    shafts: tuple[Shaft, ...] = ()

    def gear(self, gear_id: str) -> Gear:
        return next(g for g in self.gears if g.id == gear_id)

    def senses(self) -> dict[str, int]:
        """Each gear's turning sense seen from +z: +1 counter-clockwise.  The first mesh's
        driver turns counter-clockwise (a convention: its mirror image is the same train);
        an external mesh reverses the sense, an internal one (pinion and ring) and a shaft
        keep it."""
        sense = {self.reference.driver: 1}
        links = [(m.driver, m.driven, 1 if m.pair.internal else -1) for m in self.meshes]
        links += [(s.gears[0], s.gears[1], 1) for s in self.shafts]
        while len(sense) < len(self.gears):
            for a, b, flip in links:
                if a in sense and b not in sense:
                    sense[b] = flip * sense[a]
                elif b in sense and a not in sense:
                    sense[a] = flip * sense[b]
        return sense

    @property
    def reference(self) -> Mesh:
        """The mesh whose natural frequency and time origin set the scales (the first)."""
        return self.meshes[0]

    def speed_ratios(self, gear_id: str) -> dict[str, Fraction]:
        """|w_gear| / |w_(gear_id)| for every gear, exact, from the mesh tree.

        Across a mesh ``|w_driven| = |w_driver| z_driver / z_driven``.
        """
        speed = {gear_id: Fraction(1)}
        pending = list(self.meshes)
        shafts = list(self.shafts)
        while pending or shafts:
            for s in list(shafts):  # gears on one shaft turn together
                a, b = s.gears
                if a in speed or b in speed:
                    speed[b if a in speed else a] = speed[a if a in speed else b]
                    shafts.remove(s)
            for m in list(pending):
                zd, zn = self.gear(m.driver).teeth, self.gear(m.driven).teeth
                if m.driver in speed:
                    speed[m.driven] = speed[m.driver] * Fraction(zd, zn)
                elif m.driven in speed:
                    speed[m.driver] = speed[m.driven] * Fraction(zn, zd)
                else:
                    continue
                pending.remove(m)
        return speed

    def signed_speed_ratios(self, gear_id: str) -> dict[str, Fraction]:
        """w_gear / w_(gear_id) with the turning senses: ``-z1/z2`` across an external mesh,
        ``+z1/z2`` across an internal one (pinion and ring turn the same way)."""
        sense = self.senses()
        return {g: r * sense[g] * sense[gear_id] for g, r in self.speed_ratios(gear_id).items()}

    def mesh_frequency_ratios(self) -> dict[str, Fraction]:
        """Mesh frequency ``z_driver |w_driver|`` of each mesh over the reference mesh's."""
        ref = self.reference
        speed = self.speed_ratios(ref.driver)
        f_ref = self.gear(ref.driver).teeth * speed[ref.driver]
        return {m.id: self.gear(m.driver).teeth * speed[m.driver] / f_ref for m in self.meshes}

    def reference_mesh_frequency(self) -> float | None:
        """Mesh frequency of the reference mesh at the operating speed, rad/s."""
        if self.operating is None:
            return None
        ref = self.reference
        speed = self.speed_ratios(self.operating.gear)
        return float(self.gear(ref.driver).teeth * speed[ref.driver]) * self.operating.speed


def parse_topology(data: dict, source: str) -> Topology:
    """Build and validate a :class:`Topology` from parsed TOML ``data``."""
    if "planetary" in data:
        raise InputError(
            source,
            "planetary",
            "a planetary set (closed gear loops) has its linear model and modes so far: run "
            "`gearsym modes` on it; simulate, sweep, map, shoot, continue and "
            "frequency-response take trees of meshes only (issue 26)",
        )
    top = Table(data, source)
    head = top.table("topology")
    name = head.target_name("name")
    description = head.string("description", "")
    head.finish()

    materials = {"steel": STEEL}
    mats = top.table("materials", {})
    for mname in list(mats.data):
        materials[mname] = parse_material(mats.table(mname), mname)
    mats.finish()

    gears: list[Gear] = []
    for gt in top.tables("gear"):
        gear = parse_gear(gt, materials)
        if any(g.id == gear.id for g in gears):
            raise gt.error("id", f"gear '{gear.id}' is defined twice")
        gears.append(gear)
    by_id = {g.id: g for g in gears}

    meshes: list[Mesh] = []
    for mt in top.tables("mesh"):
        meshes.append(parse_mesh(mt, meshes, by_id))

    coords = {m.coordinate for m in meshes}
    for m in meshes:
        if f"d{m.coordinate}" in coords:
            raise top.error(
                "mesh",
                f"coordinates '{m.coordinate}' and 'd{m.coordinate}' clash: the derivative of "
                f"'{m.coordinate}' is named 'd{m.coordinate}'; rename one",
            )

    shafts = parse_shafts(top, by_id)
    _check_tree(top, gears, meshes, shafts)
    bearings = parse_bearings(top, by_id)
    ring = next((g.id for g in gears if g.internal), None)
    if ring is not None and (bearings or shafts):
        raise top.error(
            "bearing" if bearings else "shaft",
            f"gear '{ring}' is a ring: internal gears are supported in torsional models "
            "without bearings or shafts; remove the [[bearing]] and [[shaft]] tables",
        )

    torques: dict[str, float] = {}
    for tt in top.tables("torque") if top.has("torque") else []:
        gid = tt.string("gear")
        if gid not in by_id:
            raise tt.error("gear", f"names unknown gear '{gid}'" + nearest(gid, by_id))
        torques[gid] = torques.get(gid, 0.0) + tt.number("torque_Nm")
        tt.finish()

    operating = None
    ot = top.table("operating", None)
    if ot is not None:
        gid = ot.string("gear")
        if gid not in by_id:
            raise ot.error("gear", f"names unknown gear '{gid}'" + nearest(gid, by_id))
        operating = Operating(
            gid,
            ot.number("speed_rpm", low=0, low_open=True, high=1e6) * math.pi / 30,
            ot.number("damping_ratio", low=0.0, high=1.0),
        )
        ot.finish()
    readings = parse_readings(top, list(by_id), [m.id for m in meshes])
    top.finish()
    return Topology(
        name,
        description,
        tuple(gears),
        tuple(meshes),
        torques,
        operating,
        source,
        readings,
        bearings,
        shafts,
    )


def _check_tree(top: Table, gears: list[Gear], meshes: list[Mesh], shafts=()) -> None:
    links = [(m.driver, m.driven) for m in meshes] + [s.gears for s in shafts]
    if len(links) != len(gears) - 1:
        what = "meshes" if not shafts else "meshes and shafts"
        raise top.error(
            "mesh",
            f"{len(gears)} gears need exactly {len(gears) - 1} {what} "
            f"(a tree), got {len(links)}; closed gear loops are not "
            "supported",
        )
    reached = {meshes[0].driver}
    changed = True
    while changed:
        changed = False
        for a, b in links:
            if (a in reached) != (b in reached):
                reached |= {a, b}
                changed = True
    lost = [g.id for g in gears if g.id not in reached]
    if lost:
        raise top.error(
            "mesh",
            f"gear(s) {', '.join(lost)} are not connected to the others by any mesh"
            + (" or shaft" if shafts else ""),
        )


def load_topology(path: Path | str) -> Topology:
    """Read and validate a topology TOML file."""
    path = Path(path)
    return parse_topology(load_topology_data(path), str(path))
