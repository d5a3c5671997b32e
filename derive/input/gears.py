"""The gears of a topology: one rotating body per ``[[gear]]`` table, in SI units.

Each gear is a helical gear of ISO 21771 geometry (``derive/mesh/geometry.py``) with its
material and bore; any inertia or mass attached to it (a flywheel, a coupling) is lumped
with it.  ``parse_gear`` reads one ``[[gear]]`` table (``_mm``, ``_deg``, ``_kg_m2``,
``_kg`` keys), converts it to SI (m, rad, kg) and checks it (``internal = true``: a ring,
``derive/mesh/internal.py``, whose inertia is given); ``parse_material`` reads one
``[materials.<name>]`` table (``_Pa``, ``_kg_m3``).
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass

from ..mesh.geometry import GearGeometry, gear_geometry, with_tip_radius
from ..mesh.internal import ring_geometry, ring_with_tip_radius
from .reader import Table, nearest

__all__ = ["STEEL", "Gear", "Material", "parse_gear", "parse_material"]


@dataclass(frozen=True)
class Material:
    """A gear material: Young's modulus (Pa), Poisson's ratio, density (kg/m^3)."""

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

    @property
    def internal(self) -> bool:
        """True for a ring (internal teeth)."""
        return self.geometry.internal


def parse_material(t: Table, name: str) -> Material:
    """One ``[materials.<name>]`` table: Young's modulus (Pa), Poisson's ratio, density
    (kg/m^3)."""
    return Material(
        name=name,
        # From rubber to past diamond: beyond, the stiffness overflows or vanishes.
        youngs_modulus=t.number("youngs_modulus_Pa", low=1e6, high=1e13),
        poisson_ratio=t.number("poisson_ratio", low=0, high=0.5, high_open=True),
        density=t.number("density_kg_m3", low=10.0, high=1e5),
    )


STEEL = Material("steel", 2.06e11, 0.3, 7850.0)


def parse_gear(t: Table, materials: dict[str, Material]) -> Gear:
    """One ``[[gear]]`` table, checked and converted to SI; warns when the tip is nearly
    pointed or the teeth are undercut (the tooth models assume a full involute)."""
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
    if t.boolean("internal", False):
        return _parse_ring(
            t,
            gid,
            teeth,
            (mn, alpha_n, beta, width, shift, dedendum, rack_root),
            materials[mat_name],
        )
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


def _parse_ring(t: Table, gid: str, teeth: int, data: tuple, material: Material) -> Gear:
    """The rest of a ``[[gear]]`` table with ``internal = true``: a ring's geometry
    (``derive/mesh/internal.py``) and its given inertia (a ring's rim and housing are not
    a cylinder that the gear data fix)."""
    mn, alpha_n, beta, width, shift, dedendum, rack_root = data
    for key in ("bore_radius_mm", "mass_kg", "diametral_inertia_kg_m2"):
        if t.has(key):
            raise t.error(key, "is not used for a ring (internal = true); remove it")
    try:
        geometry = ring_geometry(teeth, mn, alpha_n, beta, shift, dedendum, rack_root)
    except ValueError as err:
        raise t.error("teeth", str(err)) from None
    tip_diameter = t.number("tip_diameter_mm", None, low=0, low_open=True)
    if tip_diameter is not None:
        try:
            geometry = ring_with_tip_radius(geometry, tip_diameter * 0.5e-3)
        except ValueError as err:
            raise t.error("tip_diameter_mm", str(err)) from None
    if geometry.tip_thickness <= 0.0:
        raise t.error(
            "profile_shift",
            f"the ring's teeth are pointed at their tip (thickness "
            f"{geometry.tip_thickness * 1e3:.3f} mm); raise its profile shift",
        )
    if not t.has("inertia_kg_m2"):
        raise t.error(
            "inertia_kg_m2",
            "a ring (internal = true) needs its polar moment of inertia (rim, web and housing "
            "together); give inertia_kg_m2",
        )
    inertia = t.number("inertia_kg_m2", low=1e-15, high=1e9)
    attached = t.number("attached_inertia_kg_m2", 0.0, low=0.0, high=1e9)
    t.finish()
    return Gear(
        gid, teeth, mn, alpha_n, beta, width, shift, material, 0.0, inertia, attached, geometry
    )
