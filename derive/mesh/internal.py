"""Internal gears (rings) and pinion-ring pairs (SI units).

A ring's teeth point inwards: with ``z`` counted positive and the profile shift ``x``
positive when it moves the ring's teeth outwards (the convention of the formulas below;
ISO 21771 writes the same pair with ``z2 < 0`` and ``x2`` of the opposite sign),

* ``r = z mt / 2``, ``r_b = r cos(alpha_t)`` as for an external gear;
* tip (inner) circle ``r_a = r - (h_a* - x) mn``, *smaller* than the reference circle;
* root (outer) circle ``r_f = r + (h_f* + x) mn``.

A pinion (external, the driver) meshing a ring (the driven gear):

* ``inv(alpha_wt) = inv(alpha_t) + 2 tan(alpha_n) (x2 - x1) / (z2 - z1)``,
  ``a_w = (r2 - r1) cos(alpha_t) / cos(alpha_wt)`` (at zero shift ``a = (d2 - d1) / 2``);
  a given ``a_w``: ``cos(alpha_wt) = (r2 - r1) cos(alpha_t) / a_w``, above ``r_b2 - r_b1``;
* path of contact ``g_alpha = sqrt(r_a1^2 - r_b1^2) - sqrt(r_a2^2 - r_b2^2) + a_w sin(alpha_wt)``,
  ``eps_alpha = g_alpha / p_bt``; the overlap ratio as for an external pair.

Both gears turn the same way: the speed ratio is ``+z1/z2``.

References
----------
ISO 21771:2007, Gears -- Cylindrical involute gears and gear pairs -- Concepts and geometry
(internal gears and internal gear pairs).
Elements of Metric Gear Technology, SDP/SI (after KHK), section 5 "Internal gears":
the same formulas with positive tooth counts, and the trochoid interference condition
(eqs. 5-6 to 5-8) checked here.
"""

from __future__ import annotations

import math
from dataclasses import replace

from .geometry import (
    TIP_MARGIN,
    CentreDistanceError,
    GearGeometry,
    PairGeometry,
    _inverse_involute,
    gear_geometry,
    involute,
    pair_geometry,
)

__all__ = [
    "internal_pair",
    "internal_pair_problem",
    "mesh_pair",
    "ring_geometry",
    "ring_with_tip_radius",
]


def ring_geometry(
    teeth: int,
    normal_module: float,
    normal_pressure_angle: float,
    helix_angle: float,
    profile_shift: float = 0.0,
    dedendum_coefficient: float = 1.25,
    root_radius_coefficient: float = 0.38,
) -> GearGeometry:
    """An internal gear (module docstring); ``ValueError`` when its tip circle does not lie
    above its base circle (no involute to mesh on)."""
    ext = gear_geometry(
        teeth,
        normal_module,
        normal_pressure_angle,
        helix_angle,
        profile_shift,
        1.0,
        dedendum_coefficient,
        root_radius_coefficient,
    )
    ring = replace(
        ext,
        tip_radius=ext.pitch_radius - (1.0 - profile_shift) * normal_module,
        root_radius=ext.pitch_radius + (dedendum_coefficient + profile_shift) * normal_module,
        internal=True,
    )
    if ring.tip_radius <= ring.base_radius:
        # r (1 - cos(alpha_t)) > (1 - x) mn: the fewest teeth whose tip clears the base.
        fewest = (
            math.floor(
                2.0
                * (1.0 - profile_shift)
                * math.cos(helix_angle)
                / (1.0 - math.cos(ext.transverse_pressure_angle))
            )
            + 1
        )
        raise ValueError(
            f"a ring of {teeth} teeth has its tip circle ({2e3 * ring.tip_radius:.3f} mm) "
            f"inside its base circle ({2e3 * ring.base_radius:.3f} mm), with no involute to "
            f"mesh on; use at least {fewest} teeth or a positive profile_shift"
        )
    return ring


def ring_with_tip_radius(ring: GearGeometry, tip_radius: float) -> GearGeometry:
    """The ring with its tip (inner) circle as drawn; ``ValueError`` unless it lies above
    the base circle, below the root circle, and no more than :data:`TIP_MARGIN` mn inside
    the standard ``r - (1 - x) mn`` (a shorter addendum, a larger tip circle, is the usual
    way to keep a ring's tip off the pinion's fillet)."""
    d_a, mn = 2e3 * tip_radius, ring.normal_module
    standard = ring.pitch_radius - (1.0 - ring.profile_shift) * mn
    if not (max(ring.base_radius, standard - TIP_MARGIN * mn) <= tip_radius < ring.root_radius):
        low = max(ring.base_radius, standard - TIP_MARGIN * mn)
        raise ValueError(
            f"{d_a:g} mm is outside the ring's possible tip circles [{2e3 * low:.3f}, "
            f"{2e3 * ring.root_radius:.3f}) mm (standard d - 2 (1 - x) mn = "
            f"{2e3 * standard:.3f} mm); give the ring's inner tip diameter in mm"
        )
    return replace(ring, tip_radius=tip_radius)


def mesh_pair(
    driver: GearGeometry,
    driven: GearGeometry,
    face_width: float,
    centre_distance: float | None = None,
) -> PairGeometry:
    """The pair geometry of any two gears: :func:`pair_geometry` for two external gears,
    :func:`internal_pair` for a pinion driving a ring; ``ValueError`` for a ring meshing a
    ring or a ring as the driver."""
    if driver.internal and driven.internal:
        raise ValueError("two rings (internal gears) cannot mesh; one must be external")
    if driver.internal:
        raise ValueError(
            "the ring is the driver; make the pinion the driver (the ring driven) -- a torque "
            "driving the ring is given as a [[torque]] of either sign"
        )
    if driven.internal:
        return internal_pair(driver, driven, face_width, centre_distance)
    return pair_geometry(driver, driven, face_width, centre_distance)


def _working(pinion: GearGeometry, ring: GearGeometry, a_w: float | None) -> tuple:
    """(alpha_wt, a_w) from the shifts, or alpha_wt at the given ``a_w`` with its checks."""
    alpha_t, tan_n = pinion.transverse_pressure_angle, math.tan(pinion.normal_pressure_angle)
    dz = ring.teeth - pinion.teeth
    a = ring.pitch_radius - pinion.pitch_radius
    shift = ring.profile_shift - pinion.profile_shift
    if a_w is None:
        inv_wt = involute(alpha_t) + 2.0 * tan_n * shift / dz
        if inv_wt <= 0:
            raise ValueError(
                f"the profile shifts (x2 - x1 = {shift:g}) leave no positive working pressure angle"
            )
        alpha_wt = alpha_t if shift == 0.0 else _inverse_involute(inv_wt)
        return alpha_wt, a * math.cos(alpha_t) / math.cos(alpha_wt)
    bases = ring.base_radius - pinion.base_radius
    mn = pinion.normal_module
    if a_w <= bases:
        raise CentreDistanceError(
            f"{a_w * 1e3:g} mm is not above the difference of the base radii of the ring and "
            f"the pinion ({bases * 1e3:.3f} mm); give the operating centre distance in mm "
            f"(zero-shift internal centre distance (d2 - d1)/2 = {a * 1e3:.3f} mm)"
        )
    if a_w > a + 2.0 * mn:
        raise CentreDistanceError(
            f"{a_w * 1e3:g} mm is more than 2 mn beyond the internal reference centre "
            f"distance (d2 - d1)/2 = {a * 1e3:.3f} mm; check the value"
        )
    alpha_wt = math.acos(a * math.cos(alpha_t) / a_w)
    fit = (involute(alpha_wt) - involute(alpha_t)) * dz / (2.0 * tan_n)
    if shift > fit + 1e-9:
        raise CentreDistanceError(
            f"{a_w * 1e3:g} mm fits profile shifts x2 - x1 = {fit:.4f} without backlash, but "
            f"x2 - x1 = {shift:g}: the teeth would jam; give a larger centre distance or lower "
            "the ring's profile shift"
        )
    return alpha_wt, a_w


def internal_pair(
    pinion: GearGeometry,
    ring: GearGeometry,
    face_width: float,
    centre_distance: float | None = None,
) -> PairGeometry:
    """Working pressure angle, centre distance and contact ratios of a pinion driving a ring
    (module docstring); ``ValueError`` when the gears cannot mesh (module, pressure or helix
    angle differ, or the ring has no more teeth than the pinion)."""
    if (pinion.normal_module, pinion.normal_pressure_angle, abs(pinion.helix_angle)) != (
        ring.normal_module,
        ring.normal_pressure_angle,
        abs(ring.helix_angle),
    ):
        raise ValueError(
            "the two gears of a pair need the same normal module, pressure "
            "angle and helix angle magnitude"
        )
    if ring.teeth <= pinion.teeth:
        raise ValueError(
            f"the ring has {ring.teeth} teeth, the pinion {pinion.teeth}: a ring needs more "
            "teeth than its pinion; swap the gears' teeth or make the larger gear the ring"
        )
    alpha_wt, a_w = _working(pinion, ring, centre_distance)
    roll1 = math.sqrt(pinion.tip_radius**2 - pinion.base_radius**2)
    roll2 = math.sqrt(ring.tip_radius**2 - ring.base_radius**2)
    g_alpha = roll1 - roll2 + a_w * math.sin(alpha_wt)
    p_bt = math.pi * pinion.transverse_module * math.cos(pinion.transverse_pressure_angle)
    start = roll2 - a_w * math.sin(alpha_wt)  # from T1, where the ring's tip meets the line
    return PairGeometry(
        driver=pinion,
        driven=ring,
        face_width=face_width,
        working_pressure_angle=alpha_wt,
        centre_distance=a_w,
        path_of_contact=g_alpha,
        transverse_base_pitch=p_bt,
        transverse_contact_ratio=g_alpha / p_bt,
        approach_length=pinion.base_radius * math.tan(alpha_wt) - start,
        axial_contact_ratio=face_width
        * math.sin(abs(pinion.helix_angle))
        / (math.pi * pinion.normal_module),
        internal=True,
    )


def _trochoid_margin(pair: PairGeometry) -> float:
    """``theta1 z1/z2 + inv(alpha_w) - inv(alpha_a2) - theta2`` (rad), >= 0 when the pinion's
    tip clears the ring's teeth as it leaves the mesh (SDP/SI, eqs. 5-6 to 5-8), with
    ``theta1 = acos((r_a2^2 - r_a1^2 - a^2) / (2 a r_a1)) + inv(alpha_a1) - inv(alpha_w)``,
    ``theta2 = acos((a^2 + r_a2^2 - r_a1^2) / (2 a r_a2))``, transverse angles."""
    p, r, a = pair.driver, pair.driven, pair.centre_distance
    ra1, ra2 = p.tip_radius, r.tip_radius
    inv_w = involute(pair.working_pressure_angle)

    def acos(v: float) -> float:
        return math.acos(min(1.0, max(-1.0, v)))

    theta1 = (
        acos((ra2**2 - ra1**2 - a**2) / (2 * a * ra1))
        + involute(math.acos(p.base_radius / ra1))
        - inv_w
    )
    theta2 = acos((a**2 + ra2**2 - ra1**2) / (2 * a * ra2))
    return theta1 * p.teeth / r.teeth + inv_w - involute(math.acos(r.base_radius / ra2)) - theta2


def internal_pair_problem(pair: PairGeometry, ends: tuple[str, str]) -> str | None:
    """Why a pinion-ring pair cannot run, in one sentence with the fix, or None.

    Checked: involute interference (the ring's tip reaching inside the pinion's base
    tangent point ``T1``), the pinion's and the ring's tips against the other's form circle
    (the fillet), tip clearance against both root circles, trochoid interference (SDP/SI eq.
    5-6: for standard 20 deg teeth it needs ``z2 - z1 > 9``) and a total contact ratio of 1.
    """
    pin, ring = ends
    p, r, a = pair.driver, pair.driven, pair.centre_distance
    if pair.start_of_contact < 0.0:
        return (
            f"involute interference: the tip of ring '{ring}' reaches "
            f"{-pair.start_of_contact * 1e3:.3f} mm past the base tangent point of '{pin}'; "
            "use more teeth on the pinion or a positive profile shift on it"
        )
    (sap1, _), (sap2, _) = pair.active_radii
    if sap1 < p.form_radius * (1 - 1e-12):
        return (
            f"tip interference: the tip of ring '{ring}' meets '{pin}' at radius "
            f"{sap1 * 1e3:.3f} mm, below its form circle ({p.form_radius * 1e3:.3f} mm), in "
            "the fillet; give the ring a larger tip_diameter_mm (a shorter addendum) or the "
            "pinion a smaller rack_root_radius"
        )
    if sap2 > r.form_radius * (1 + 1e-12):
        return (
            f"tip interference: the tip of '{pin}' meets ring '{ring}' at radius "
            f"{sap2 * 1e3:.3f} mm, beyond its form circle ({r.form_radius * 1e3:.3f} mm), in "
            "the fillet; lower the pinion's profile shift or deepen the ring's rack_dedendum"
        )
    for gap, tip, root in (
        (r.root_radius - a - p.tip_radius, pin, ring),
        (r.tip_radius - a - p.root_radius, ring, pin),
    ):
        if gap < 0.0:
            return (
                f"the tip of '{tip}' runs {-gap * 1e3:.3f} mm into the root circle of "
                f"'{root}' (negative tip clearance); lower the profile shifts or deepen the "
                "rack_dedendum"
            )
    margin = _trochoid_margin(pair)
    if margin < 0.0:
        return (
            f"trochoid interference: the tip of '{pin}' fouls the teeth of ring '{ring}' as "
            f"it leaves the mesh ({r.teeth} - {p.teeth} = {r.teeth - p.teeth} teeth apart, "
            f"margin {margin:.5f} rad; SDP/SI eq. 5-6); use a larger tooth difference "
            "(more than 9 for standard 20 deg teeth) or profile shifts"
        )
    if pair.total_contact_ratio < 1.0:
        return (
            f"total contact ratio {pair.total_contact_ratio:.3f} is below 1: the pair cannot "
            "transmit motion continuously"
        )
    return None
