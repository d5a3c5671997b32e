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
"""

from __future__ import annotations

import math
import re
import warnings
from dataclasses import dataclass, field
from fractions import Fraction
from pathlib import Path

from ..mesh.geometry import (
    CentreDistanceError,
    GearGeometry,
    PairGeometry,
    gear_geometry,
    pair_geometry,
    with_tip_radius,
)
from ..mesh.pem import pem_stiffness
from ..mesh.stiffness import MeshStiffness, contact_line_stiffness
from .reader import Table, nearest
from .readings import ORIENTATIONS, parse_readings
from .supports import Bearing, Shaft, load_topology_data, parse_bearings, parse_shafts

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

# Names the generated code uses itself; coordinates may not take them.
_RESERVED = {"tau", "x", "p", "np", "ca", "omega", "out", "jac", "rhs"}
_BACKLASH_NAME = re.compile(r"g[0-9]+")


@dataclass(frozen=True)
class Material:
    name: str
    youngs_modulus: float  # Pa
    poisson_ratio: float
    density: float  # kg/m^3


@dataclass(frozen=True)
class Gear:
    """One rotating body: a helical gear and any inertia lumped with it (SI units)."""

    id: str
    teeth: int
    normal_module: float
    normal_pressure_angle: float
    helix_angle: float
    face_width: float
    profile_shift: float
    material: Material
    bore_radius: float
    inertia_given: float | None
    attached_inertia: float
    geometry: GearGeometry
    mass_given: float | None = None
    attached_mass: float = 0.0
    diametral_inertia_given: float | None = None

    @property
    def blank_inertia(self) -> float:
        """Solid cylinder of pitch radius r with a bore: ``rho pi b (r^4 - r_bore^4) / 2``."""
        r, rb = self.geometry.pitch_radius, self.bore_radius
        return 0.5 * self.material.density * math.pi * self.face_width * (r**4 - rb**4)

    @property
    def gear_inertia(self) -> float:
        return self.inertia_given if self.inertia_given is not None else self.blank_inertia

    @property
    def inertia(self) -> float:
        """Total polar moment of inertia of the body, kg m^2."""
        return self.gear_inertia + self.attached_inertia

    @property
    def mass(self) -> float:
        """Total mass of the body, kg: given, or the blank ``rho pi b (r^2 - r_bore^2)``
        (the same cylinder as the inertia), plus any attached mass."""
        if self.mass_given is not None:
            return self.mass_given + self.attached_mass
        r, rb = self.geometry.pitch_radius, self.bore_radius
        return self.material.density * math.pi * self.face_width * (r**2 - rb**2) + (
            self.attached_mass
        )

    @property
    def diametral_inertia(self) -> float:
        """Moment of inertia about a diameter through the face centre, kg m^2 (tilting
        models): given, or the blank's ``m (3 (r^2 + r_bore^2) + b^2) / 12`` plus half the
        attached inertia (a thin disc's)."""
        if self.diametral_inertia_given is not None:
            return self.diametral_inertia_given
        r, rb, b = self.geometry.pitch_radius, self.bore_radius, self.face_width
        blank = self.material.density * math.pi * b * (r**2 - rb**2)
        return blank * (3 * (r**2 + rb**2) + b**2) / 12 + self.attached_inertia / 2

    @property
    def base_radius(self) -> float:
        return self.geometry.base_radius


@dataclass(frozen=True)
class TransmissionError:
    """Composite transmission error ``e(t) = sum_h a_h cos(h we t + phase_h)`` (m, rad)."""

    amplitudes: tuple[float, ...] = ()
    phases: tuple[float, ...] = ()


@dataclass(frozen=True)
class Mesh:
    """One gear pair.  ``driver`` pushes ``driven``; the coordinate is positive when the
    driver's working flanks are loaded (forward meshing), or, with ``orientation = -1``
    (``orientation = "reversed"``, see ``derive.readings``), measured the other way."""

    id: str
    driver: str
    driven: str
    coordinate: str
    half_backlash: float
    stiffness: MeshStiffness
    transmission_error: TransmissionError
    phase: float  # stiffness/TE phase lag relative to the reference mesh, rad
    phase_source: str
    pair: PairGeometry
    orientation: int = 1  # +1: coordinate positive on the driver's flank; -1: reversed
    # Angle of the driver's centre round the driven gear's, from +x, counter-clockwise seen
    # from +z (the axes' direction), rad: it sets the line of action's direction.
    driver_position: float = 0.0


@dataclass(frozen=True)
class Operating:
    gear: str
    speed: float  # rad/s
    damping_ratio: float


@dataclass(frozen=True)
class Topology:
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
        an external mesh reverses the sense, a shaft keeps it."""
        sense = {self.reference.driver: 1}
        links = [(m.driver, m.driven, -1) for m in self.meshes]
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


def _material(t: Table, name: str) -> Material:
    return Material(
        name=name,
        # From rubber to past diamond: beyond, the stiffness overflows or vanishes.
        youngs_modulus=t.number("youngs_modulus_Pa", low=1e6, high=1e13),
        poisson_ratio=t.number("poisson_ratio", low=0, high=0.5, high_open=True),
        density=t.number("density_kg_m3", low=10.0, high=1e5),
    )


_STEEL = Material("steel", 2.06e11, 0.3, 7850.0)


def _gear(t: Table, materials: dict[str, Material]) -> Gear:
    gid = t.identifier("id")
    # Upper limits far beyond any gear built (marine wheels have a few hundred teeth, a
    # module up to about 50 mm and a face under 2 m): past them the input is a typo.
    teeth = t.integer("teeth", low=5, high=10_000)
    mn = t.number("normal_module_mm", low=0, low_open=True, high=1000.0) * 1e-3
    alpha_n = math.radians(t.number("normal_pressure_angle_deg", 20.0, low=10.0, high=35.0))
    beta = math.radians(t.number("helix_angle_deg", 0.0, low=-45.0, high=45.0))
    width = t.number("face_width_mm", low=0, low_open=True, high=10_000.0) * 1e-3
    shift = t.number("profile_shift", 0.0, low=-1.0, high=1.5)
    mat_name = t.string("material", "steel")
    if mat_name not in materials:
        raise t.error(
            "material",
            f"'{mat_name}' is not defined"
            + nearest(mat_name, materials)
            + f"; materials: {', '.join(sorted(materials))}",
        )
    dedendum = t.number("rack_dedendum", 1.25, low=1.0, high=1.6)
    rack_root = t.number("rack_root_radius", 0.38, low=0.0, high=0.6)
    try:
        geometry = gear_geometry(teeth, mn, alpha_n, beta, shift, 1.0, dedendum, rack_root)
    except ValueError as err:
        raise t.error("rack_root_radius", str(err)) from None
    tip_diameter = t.number("tip_diameter_mm", None, low=0, low_open=True)
    if tip_diameter is not None:
        try:
            geometry = with_tip_radius(geometry, tip_diameter * 0.5e-3)
        except ValueError as err:
            raise t.error("tip_diameter_mm", str(err)) from None
    sa = geometry.tip_thickness
    if sa <= 0.0:
        raise t.error(
            "profile_shift",
            f"{teeth} teeth with profile shift {shift:g} are pointed (tip thickness "
            f"{sa * 1e3:.3f} mm); lower the profile shift",
        )
    if sa < 0.2 * mn:
        warnings.warn(
            f"{t.where('profile_shift')}: tip thickness {sa * 1e3:.3f} mm is below 0.2 mn; the "
            "tip is nearly pointed -- lower the profile shift",
            stacklevel=2,
        )
    if geometry.undercut:
        warnings.warn(
            f"{t.where('teeth')}: {teeth} teeth with profile shift {shift:g} are undercut by the "
            "generating rack; the tooth-stiffness models assume a full involute -- raise "
            "profile_shift",
            stacklevel=2,
        )
    # Default bore: h_f = r_f / r_int = 3, inside the range of the fillet-foundation formula
    # (Sainsot et al. 2004: 1.4 <= h_f <= 7).
    bore = t.number("bore_radius_mm", geometry.root_radius / 3.0 * 1e3, low=0.0) * 1e-3
    if bore >= geometry.root_radius:
        raise t.error(
            "bore_radius_mm",
            f"{bore * 1e3:g} mm must be below the root radius {geometry.root_radius * 1e3:.3f} mm",
        )
    # 1e-15 to 1e9 kg m^2: a watch gear to a ship's propeller shaft line many times over;
    # outside, the modes and scales overflow.
    inertia = t.number("inertia_kg_m2", None, low=1e-15, high=1e9)
    attached = t.number("attached_inertia_kg_m2", 0.0, low=0.0, high=1e9)
    mass = t.number("mass_kg", None, low=0, low_open=True, high=1e6)
    attached_mass = t.number("attached_mass_kg", 0.0, low=0.0, high=1e6)
    diametral = t.number("diametral_inertia_kg_m2", None, low=1e-15, high=1e9)
    t.finish()
    return Gear(
        gid,
        teeth,
        mn,
        alpha_n,
        beta,
        width,
        shift,
        materials[mat_name],
        bore,
        inertia,
        attached,
        geometry,
        mass,
        attached_mass,
        diametral,
    )


def _stiffness(t: Table, pair: PairGeometry, gears: tuple[Gear, Gear]) -> MeshStiffness:
    # An open value (derive/input/open_values.py): a factor on every harmonic, the mean kept.
    scale = t.number("harmonic_scale", 1.0, low=0.0)
    k = _stiffness_of(t, pair, gears)
    if scale == 1.0:
        return k
    return MeshStiffness(
        k.mean, tuple(scale * c for c in k.cos), tuple(scale * c for c in k.sin), k.source
    )


def _stiffness_of(t: Table, pair: PairGeometry, gears: tuple[Gear, Gear]) -> MeshStiffness:
    source = t.string("source", choices=("harmonics", "contact-line", "potential-energy"))
    if source == "potential-energy":
        return _pem_stiffness(t, pair, gears)
    # 1 kN/mm-scale plastics down to 1e3 N/m, steel's 1e8-1e10 N/m up to 1e13 N/m.
    mean = t.number("mean_N_per_m", low=1e3, high=1e13)
    if source == "harmonics":
        cos = t.numbers("cos_N_per_m", [])
        sin = t.numbers("sin_N_per_m", [])
        if len(cos) != len(sin):
            raise t.error("sin_N_per_m", f"needs as many entries as cos_N_per_m ({len(cos)})")
        t.finish()
        return MeshStiffness(mean, cos, sin, "harmonics")
    harmonics = t.integer("harmonics", 10, low=0, high=64)
    t.finish()
    return contact_line_stiffness(
        mean, pair.transverse_contact_ratio, pair.axial_contact_ratio, harmonics
    )


def _pem_stiffness(t: Table, pair: PairGeometry, gears: tuple[Gear, Gear]) -> MeshStiffness:
    """Sliced potential-energy stiffness (``derive/mesh/pem.py``); the Fourier coefficients are
    rounded to 9 significant digits so that generated files do not depend on the last bits
    of the FFT."""
    slices = t.integer("slices", 200, low=1, high=100000)
    harmonics = t.integer("harmonics", 10, low=0, high=64)
    samples = t.integer("samples", 2048, low=64, high=1 << 20)
    if 2 * harmonics >= samples:
        raise t.error("samples", f"needs more than {2 * harmonics} samples per mesh period")
    t.finish()
    for gear in gears:
        if gear.geometry.undercut:
            raise t.error(
                "source",
                f"gear '{gear.id}' is undercut; the potential-energy tooth model assumes a full "
                "involute -- raise its profile_shift or give the stiffness as harmonics",
            )
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            res = pem_stiffness(
                pair,
                [(g.material.youngs_modulus, g.material.poisson_ratio) for g in gears],
                [g.bore_radius for g in gears],
                slices=slices,
                harmonics=harmonics,
                samples=samples,
                names=tuple(g.id for g in gears),
            )
        except ValueError as err:
            raise t.error(
                "source", f"the potential-energy method cannot be applied: {err}"
            ) from None
    for w in caught:
        warnings.warn(f"{t.where('source')}: {w.message}", stacklevel=3)

    def r9(x: float) -> float:
        return float(f"{x:.9g}")

    return MeshStiffness(
        r9(res.mean),
        tuple(r9(c) for c in res.cos),
        tuple(r9(c) for c in res.sin),
        "potential-energy",
    )


def _check_contact(t: Table, pair: PairGeometry, ends: list[str]) -> None:
    """Involute contact must stay above both base circles, and the total contact ratio
    must reach 1 (for helical gears the overlap counts: eps_gamma = eps_alpha + eps_beta)."""
    approach = pair.approach_length
    recess = pair.path_of_contact - approach
    for length, gear, other in ((approach, ends[0], ends[1]), (recess, ends[1], ends[0])):
        base = pair.driver if gear == ends[0] else pair.driven
        available = base.base_radius * math.tan(pair.working_pressure_angle)
        if length > available * (1 + 1e-12):
            raise t.error(
                "driven",
                f"involute interference: the tip of '{other}' reaches below the base circle of "
                f"'{gear}' ({length * 1e3:.3f} mm of contact path against {available * 1e3:.3f} "
                "mm available); use more teeth or a positive profile shift",
            )
    for tip, root, a, b in (
        (pair.driver, pair.driven, ends[0], ends[1]),
        (pair.driven, pair.driver, ends[1], ends[0]),
    ):
        clearance = pair.centre_distance - tip.tip_radius - root.root_radius
        if clearance < 0.0:
            raise t.error(
                "driven",
                f"the tip of '{a}' runs {-clearance * 1e3:.3f} mm into the root circle of "
                f"'{b}' (negative tip clearance); lower the profile shifts or deepen the "
                "rack_dedendum",
            )
    (sap1, _), (sap2, _) = pair.active_radii
    for sap, geo, gear, other in (
        (sap1, pair.driver, ends[0], ends[1]),
        (sap2, pair.driven, ends[1], ends[0]),
    ):
        if sap < geo.form_radius * (1 - 1e-12):
            raise t.error(
                "driven",
                f"tip interference: the tip of '{other}' meets '{gear}' at radius "
                f"{sap * 1e3:.3f} mm, below its form circle ({geo.form_radius * 1e3:.3f} mm), "
                "in the fillet; use a positive profile shift on it or a smaller rack_root_radius",
            )
    if pair.total_contact_ratio < 1.0:
        raise t.error(
            "driven",
            f"total contact ratio {pair.total_contact_ratio:.3f} is below 1: the pair cannot "
            "transmit motion continuously",
        )


def _phase(t: Table, meshes: list, ends: list[str], by_id: dict) -> tuple[float, str]:
    """Stiffness/transmission-error phase lag of a mesh relative to the first mesh.

    Either given (``stiffness_phase_deg``) or from the layout (``layout_angle_deg``): a mesh
    that shares a gear with the first mesh, in the same role (driver or driven in both),
    whose other centre lies an angle psi further round that gear in its direction of
    rotation, sees each tooth psi / w later -- a lag of z psi / 360 teeth, i.e.
    2 pi delta with delta the fractional part of z psi / 360 deg.
    """
    given, angle = t.has("stiffness_phase_deg"), t.has("layout_angle_deg")
    if not (given or angle):
        return 0.0, "reference" if not meshes else "none given"
    if not meshes:
        raise t.error(
            "layout_angle_deg" if angle else "stiffness_phase_deg",
            "the first mesh sets the time origin and takes no phase; give phases on the "
            "other meshes",
        )
    if given and angle:
        raise t.error(
            "layout_angle_deg", "give either stiffness_phase_deg or layout_angle_deg, not both"
        )
    if given:
        return math.radians(t.number("stiffness_phase_deg")), "given"
    psi = t.number("layout_angle_deg", low=-360.0, high=360.0)
    ref = meshes[0]
    common = sorted({ends[0], ends[1]} & {ref.driver, ref.driven})
    if not common:
        raise t.error(
            "layout_angle_deg",
            f"needs a mesh that shares a gear with the first mesh '{ref.id}'",
        )
    gear = common[0]
    role_ref = "driver" if ref.driver == gear else "driven"
    role_here = "driver" if ends[0] == gear else "driven"
    if role_ref != role_here:
        raise t.error(
            "layout_angle_deg",
            f"gear '{gear}' is the {role_ref} in mesh '{ref.id}' but the {role_here} here: "
            "opposite flanks carry the load, which this layout rule does not cover; give "
            "stiffness_phase_deg instead",
        )
    teeth = by_id[gear].teeth * psi / 360.0
    delta = teeth - math.floor(teeth)
    return 2.0 * math.pi * delta, (
        f"layout: {psi:g} deg round gear '{gear}' spans {teeth:.4f} teeth, delta = {delta:.4f}"
    )


def _transmission_error(t: Table | None) -> TransmissionError:
    if t is None:
        return TransmissionError()
    amps = t.numbers("amplitude_um", low=0.0)
    phases = t.numbers("phase_deg", [0.0] * len(amps), length=len(amps))
    t.finish()
    return TransmissionError(tuple(a * 1e-6 for a in amps), tuple(math.radians(p) for p in phases))


def parse_topology(data: dict, source: str) -> Topology:
    """Build and validate a :class:`Topology` from parsed TOML ``data``."""
    top = Table(data, source)
    head = top.table("topology")
    name = head.target_name("name")
    description = head.string("description", "")
    head.finish()

    materials = {"steel": _STEEL}
    mats = top.table("materials", {})
    for mname in list(mats.data):
        materials[mname] = _material(mats.table(mname), mname)
    mats.finish()

    gears: list[Gear] = []
    for gt in top.tables("gear"):
        gear = _gear(gt, materials)
        if any(g.id == gear.id for g in gears):
            raise gt.error("id", f"gear '{gear.id}' is defined twice")
        gears.append(gear)
    by_id = {g.id: g for g in gears}

    meshes: list[Mesh] = []
    for mt in top.tables("mesh"):
        mid = mt.identifier("id")
        ends = []
        for end in ("driver", "driven"):
            gid = mt.string(end)
            if gid not in by_id:
                raise mt.error(
                    end,
                    f"names unknown gear '{gid}'"
                    + nearest(gid, by_id)
                    + f"; gears: {', '.join(by_id)}",
                )
            ends.append(gid)
        if ends[0] == ends[1]:
            raise mt.error("driven", f"a gear cannot mesh with itself ('{ends[0]}')")
        g1, g2 = by_id[ends[0]], by_id[ends[1]]
        a_w = mt.number("centre_distance_mm", None, low=0, low_open=True)
        try:
            pair = pair_geometry(
                g1.geometry,
                g2.geometry,
                min(g1.face_width, g2.face_width),
                None if a_w is None else a_w * 1e-3,
            )
        except CentreDistanceError as err:
            raise mt.error("centre_distance_mm", str(err)) from None
        except ValueError as err:
            raise mt.error("driven", f"'{ends[0]}' and '{ends[1]}' cannot mesh: {err}") from None
        _check_contact(mt, pair, ends)
        coordinate = mt.identifier("coordinate")
        if coordinate in _RESERVED or _BACKLASH_NAME.fullmatch(coordinate):
            raise mt.error(
                "coordinate",
                f"'{coordinate}' is reserved; avoid {', '.join(sorted(_RESERVED))} and g1, g3, ...",
            )
        backlash = mt.number("half_backlash_um", low=0, low_open=True) * 1e-6
        stiffness = _stiffness(mt.table("stiffness"), pair, (g1, g2))
        te = _transmission_error(mt.table("transmission_error", None))
        phase, phase_source = _phase(mt, meshes, ends, by_id)
        orientation = mt.string("orientation", "forward", choices=ORIENTATIONS)
        position = math.radians(mt.number("driver_position_deg", 0.0, low=-360.0, high=360.0))
        mt.finish()
        for other in meshes:
            if other.id == mid:
                raise mt.error("id", f"mesh '{mid}' is defined twice")
            if other.coordinate == coordinate:
                raise mt.error("coordinate", f"'{coordinate}' is already used by mesh '{other.id}'")
            if {other.driver, other.driven} == set(ends):
                raise mt.error(
                    "driven", f"gears '{ends[0]}' and '{ends[1]}' already mesh in '{other.id}'"
                )
        meshes.append(
            Mesh(
                mid,
                ends[0],
                ends[1],
                coordinate,
                backlash,
                stiffness,
                te,
                phase,
                phase_source,
                pair,
                ORIENTATIONS[orientation],
                position,
            )
        )

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
