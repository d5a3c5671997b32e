"""Involute helical gear geometry of external pairs (SI units).

Formulas follow ISO 21771 (gear nomenclature and geometry) for standard basic-rack
teeth: addendum ``(1 + x) mn``, working pressure angle from the involute function,
transverse contact ratio from the path of contact, overlap (axial) ratio
``b sin(beta) / (pi mn)``.

References
----------
ISO 21771:2007, Gears -- Cylindrical involute gears and gear pairs -- Concepts and geometry.
ISO 6336-1:2019, Calculation of load capacity of spur and helical gears, Part 1.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from scipy.optimize import brentq

__all__ = ["GearGeometry", "PairGeometry", "gear_geometry", "pair_geometry", "involute"]


def involute(alpha: float) -> float:
    """inv(alpha) = tan(alpha) - alpha."""
    return math.tan(alpha) - alpha


def _inverse_involute(value: float) -> float:
    return brentq(lambda a: involute(a) - value, 1e-9, math.radians(89.0), xtol=1e-15)


@dataclass(frozen=True)
class GearGeometry:
    """Transverse geometry of one helical gear (lengths in m, angles in rad)."""

    teeth: int
    normal_module: float
    normal_pressure_angle: float
    helix_angle: float
    profile_shift: float
    transverse_module: float
    transverse_pressure_angle: float
    base_helix_angle: float
    pitch_radius: float
    base_radius: float
    tip_radius: float
    root_radius: float


def gear_geometry(
    teeth: int,
    normal_module: float,
    normal_pressure_angle: float,
    helix_angle: float,
    profile_shift: float = 0.0,
    addendum_coefficient: float = 1.0,
    dedendum_coefficient: float = 1.25,
) -> GearGeometry:
    """Transverse quantities of an external helical gear.

    ``mt = mn / cos(beta)``, ``tan(alpha_t) = tan(alpha_n) / cos(beta)``,
    ``r = z mt / 2``, ``r_b = r cos(alpha_t)``, ``sin(beta_b) = sin(beta) cos(alpha_n)``,
    ``r_a = r + (h_a* + x) mn``, ``r_f = r - (h_f* - x) mn``.
    """
    mt = normal_module / math.cos(helix_angle)
    alpha_t = math.atan(math.tan(normal_pressure_angle) / math.cos(helix_angle))
    r = teeth * mt / 2.0
    return GearGeometry(
        teeth=teeth,
        normal_module=normal_module,
        normal_pressure_angle=normal_pressure_angle,
        helix_angle=helix_angle,
        profile_shift=profile_shift,
        transverse_module=mt,
        transverse_pressure_angle=alpha_t,
        base_helix_angle=math.asin(math.sin(helix_angle) * math.cos(normal_pressure_angle)),
        pitch_radius=r,
        base_radius=r * math.cos(alpha_t),
        tip_radius=r + (addendum_coefficient + profile_shift) * normal_module,
        root_radius=r - (dedendum_coefficient - profile_shift) * normal_module,
    )


@dataclass(frozen=True)
class PairGeometry:
    """Geometry of an external pair: working centre distance and contact ratios."""

    driver: GearGeometry
    driven: GearGeometry
    face_width: float
    working_pressure_angle: float
    centre_distance: float
    path_of_contact: float
    transverse_base_pitch: float
    transverse_contact_ratio: float
    axial_contact_ratio: float
    approach_length: float

    @property
    def total_contact_ratio(self) -> float:
        return self.transverse_contact_ratio + self.axial_contact_ratio


def pair_geometry(driver: GearGeometry, driven: GearGeometry, face_width: float) -> PairGeometry:
    """Working pressure angle, centre distance and contact ratios of an external pair.

    ``inv(alpha_wt) = inv(alpha_t) + 2 tan(alpha_n) (x1 + x2) / (z1 + z2)``,
    ``a_w = (r1 + r2) cos(alpha_t) / cos(alpha_wt)``,
    ``g_alpha = sqrt(ra1^2 - rb1^2) + sqrt(ra2^2 - rb2^2) - a_w sin(alpha_wt)``,
    ``eps_alpha = g_alpha / p_bt``, ``eps_beta = b sin(beta) / (pi mn)`` (ISO 21771).
    """
    if (driver.normal_module, driver.normal_pressure_angle, abs(driver.helix_angle)) != (
        driven.normal_module,
        driven.normal_pressure_angle,
        abs(driven.helix_angle),
    ):
        raise ValueError(
            "the two gears of a pair need the same normal module, pressure "
            "angle and helix angle magnitude"
        )
    alpha_t = driver.transverse_pressure_angle
    shift = driver.profile_shift + driven.profile_shift
    inv_wt = involute(alpha_t) + 2.0 * math.tan(driver.normal_pressure_angle) * shift / (
        driver.teeth + driven.teeth
    )
    if inv_wt <= 0:
        raise ValueError(
            f"the profile shifts (x1 + x2 = {shift:g}) leave no positive working pressure angle"
        )
    alpha_wt = alpha_t if shift == 0.0 else _inverse_involute(inv_wt)
    a_w = (driver.pitch_radius + driven.pitch_radius) * math.cos(alpha_t) / math.cos(alpha_wt)
    g_alpha = (
        math.sqrt(driver.tip_radius**2 - driver.base_radius**2)
        + math.sqrt(driven.tip_radius**2 - driven.base_radius**2)
        - a_w * math.sin(alpha_wt)
    )
    p_bt = math.pi * driver.transverse_module * math.cos(alpha_t)
    return PairGeometry(
        driver=driver,
        driven=driven,
        face_width=face_width,
        working_pressure_angle=alpha_wt,
        centre_distance=a_w,
        path_of_contact=g_alpha,
        transverse_base_pitch=p_bt,
        transverse_contact_ratio=g_alpha / p_bt,
        approach_length=math.sqrt(driven.tip_radius**2 - driven.base_radius**2)
        - driven.base_radius * math.tan(alpha_wt),
        axial_contact_ratio=face_width
        * math.sin(abs(driver.helix_angle))
        / (math.pi * driver.normal_module),
    )
