"""Compliance of one tooth pair per unit face width, by the potential-energy method.

One tooth is a non-uniform cantilever in the transverse plane, loaded along the line of
action at its contact point.  Its compliance is the sum of

* bending, shear and axial compression of the tooth, integrated along the tooth centreline
  in the involute roll angle ``t`` (the tooth clamped at the root circle; where the root
  circle lies below the base circle, the part between them is a straight-sided section of
  the base-circle thickness) -- Yang and Lin (1987), "Hertzian damping, tooth friction and
  bending elasticity in gear impact dynamics", J. Mech. Trans. Autom. Des. 109; Tian (2004),
  "Dynamic simulation for system response of gearbox including localized gear faults",
  MSc thesis, University of Alberta; Chen and Shao (2011), "Analytical mesh stiffness
  calculation of spur gear pairs with tooth root crack", Eng. Fail. Anal. 18;
* the fillet-foundation (gear body) deflection of Sainsot, Velex and Duverger (2004),
  "Contribution of gear body to tooth deflections -- a new bidimensional analytical
  formula", J. Mech. Des. 126(4) 748-752, whose coefficient table is the checked data file
  ``derive/mesh/data/sainsot2004.toml``;

and, once per pair, the linearised Hertzian contact compliance of two cylinders of the
same length, ``1/k_h = 2 / (pi L E*)``, ``1/E* = (1-nu1^2)/E1 + (1-nu2^2)/E2`` (for equal
materials ``k_h = pi E L / (4 (1 - nu^2))``, Yang and Lin 1987).

Every term is a compliance inversely proportional to the loaded width ``L``; functions here
return compliances for unit width (m^2/N), which a slice of width ``dz`` divides by ``dz``
(``derive/mesh/pem.py`` sums the slices over a mesh cycle).
"""

from __future__ import annotations

import math
import tomllib
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .geometry import GearGeometry, PairGeometry, involute

__all__ = [
    "FOUNDATION_TABLE",
    "SainsotTable",
    "foundation_parameters",
    "foundation_warnings",
    "hertz_compliance",
    "pair_compliance",
    "tooth_compliance",
]

_NODES, _WEIGHTS = np.polynomial.legendre.leggauss(48)


@dataclass(frozen=True)
class SainsotTable:
    """Coefficients ``A..F`` of ``X*(h_f, theta_f) = A/theta_f^2 + B h_f^2 + C h_f/theta_f
    + D/theta_f + E h_f + F`` for ``X* = L*, M*, P*, Q*`` and the range they were fitted on."""

    coefficients: dict[str, tuple[float, ...]]
    hf_range: tuple[float, float]
    theta_range: tuple[float, float]
    source: str

    def value(self, name: str, hf, theta):
        a, b, c, d, e, f = self.coefficients[name]
        return a / theta**2 + b * hf**2 + c * hf / theta + d / theta + e * hf + f


def _load_table(path: Path) -> SainsotTable:
    with open(path, "rb") as fh:
        data = tomllib.load(fh)
    coefficients = {}
    for name in ("L", "M", "P", "Q"):
        row = tuple(float(v) for v in data["coefficients"][name])
        if len(row) != 6 or not all(math.isfinite(v) for v in row):
            raise ValueError(f"{path}: coefficients.{name} needs six finite numbers A..F")
        coefficients[name] = row
    valid = data["validity"]
    return SainsotTable(
        coefficients,
        (float(valid["hf_min"]), float(valid["hf_max"])),
        (float(valid["theta_min"]), float(valid["theta_max"])),
        data["source"],
    )


FOUNDATION_TABLE = _load_table(Path(__file__).with_name("data") / "sainsot2004.toml")


def hertz_compliance(e1: float, nu1: float, e2: float, nu2: float) -> float:
    """Linearised Hertzian compliance of a line contact per unit length (m^2/N):
    ``2 / (pi E*)`` with ``1/E* = (1 - nu1^2)/E1 + (1 - nu2^2)/E2``."""
    return 2.0 / math.pi * ((1.0 - nu1**2) / e1 + (1.0 - nu2**2) / e2)


def _root_half_angle(gear: GearGeometry) -> float:
    """Half the angle the tooth subtends at the root circle (``theta_f`` of Sainsot 2004)."""
    rb, rf, a2 = gear.base_radius, gear.root_radius, gear.base_half_angle
    if rf > rb:
        return a2 - involute(math.acos(rb / rf))
    hb = rb * math.sin(a2)
    if hb >= rf:
        raise ValueError(
            f"{gear.teeth} teeth: the root circle ({rf * 1e3:.3f} mm) is narrower than the "
            "tooth at the base circle; the tooth model does not apply -- use more teeth"
        )
    return math.asin(hb / rf)


def foundation_parameters(gear: GearGeometry, bore_radius: float) -> tuple[float, float]:
    """``(h_f, theta_f)`` of Sainsot 2004: root over bore radius, and the root half angle."""
    if bore_radius <= 0.0:
        raise ValueError("the fillet-foundation stiffness needs the gear blank's bore radius (> 0)")
    return gear.root_radius / bore_radius, _root_half_angle(gear)


def foundation_warnings(gear: GearGeometry, bore_radius: float, name: str = "gear") -> list[str]:
    """Messages for each of ``h_f``, ``theta_f`` outside the range the table was fitted on."""
    hf, theta = foundation_parameters(gear, bore_radius)
    table = FOUNDATION_TABLE
    out = []
    lo, hi = table.hf_range
    if not lo <= hf <= hi:
        out.append(
            f"{name}: root/bore radius ratio h_f = {hf:.3f} is outside [{lo:g}, {hi:g}], the "
            "range of the fillet-foundation formula (Sainsot et al. 2004); change the bore radius"
        )
    lo, hi = table.theta_range
    if not lo <= theta <= hi:
        out.append(
            f"{name}: root half angle theta_f = {theta:.4f} rad is outside [{lo:g}, {hi:g}] rad "
            "(for 20 deg teeth without profile shift, about 17 to 245 teeth), the range of the "
            "fillet-foundation formula (Sainsot et al. 2004)"
        )
    return out


def tooth_compliance(
    gear: GearGeometry, youngs: float, poisson: float, bore_radius: float, roll
) -> dict[str, np.ndarray]:
    """Compliances per unit width (m^2/N) of one tooth loaded at involute roll angles ``roll``.

    Returns ``bending``, ``shear``, ``axial`` and ``foundation`` arrays shaped like ``roll``.
    The roll angle ``t`` of a point at radius ``r`` is ``sqrt(r^2/r_b^2 - 1)``; the force
    acts along the line of action at ``alpha_m = t - alpha_2`` from the perpendicular to the
    tooth centreline, ``alpha_2`` the half angle of the tooth at the base circle.
    """
    t = np.asarray(roll, dtype=float)
    rb, rf, a2 = gear.base_radius, gear.root_radius, gear.base_half_angle
    shear_modulus = youngs / (2.0 * (1.0 + poisson))
    am = t - a2
    cam, sam = np.cos(am), np.sin(am)
    hc = rb * (np.sin(a2 - t) + t * np.cos(a2 - t))  # half thickness at the contact point
    yc = rb * (np.cos(a2 - t) - t * np.sin(a2 - t))  # its distance from the centre
    t0 = math.sqrt((rf / rb) ** 2 - 1.0) if rf > rb else 0.0
    if np.any(t < t0):
        raise ValueError("contact below the root circle: the tooth model does not apply")
    # Involute part: y(tau), h(tau) with dy/dtau = rb tau cos(a2 - tau), Gauss-Legendre.
    half = (t - t0)[..., None] / 2.0
    tau = t0 + half * (_NODES + 1.0)
    w = half * _WEIGHTS
    h = rb * (np.sin(a2 - tau) + tau * np.cos(a2 - tau))
    y = rb * (np.cos(a2 - tau) - tau * np.sin(a2 - tau))
    dy = rb * tau * np.cos(a2 - tau) * w
    arm = (yc[..., None] - y) * cam[..., None] - hc[..., None] * sam[..., None]
    bending = np.sum(12.0 * arm**2 / (youngs * (2.0 * h) ** 3) * dy, axis=-1)
    inv_area = np.sum(dy / (2.0 * h), axis=-1)  # integral of dy / A for unit width
    shear = 1.2 * cam**2 / shear_modulus * inv_area
    axial = sam**2 / youngs * inv_area
    if rf < rb:
        # Straight-sided section of half thickness h_b from the root to the base circle.
        hb = rb * math.sin(a2)
        y_root, y_base = math.sqrt(rf**2 - hb**2), rb * math.cos(a2)

        def arm_at(yy):
            return (yc - yy) * cam - hc * sam

        bending = bending + 12.0 / (youngs * 8.0 * hb**3) * (
            arm_at(y_root) ** 3 - arm_at(y_base) ** 3
        ) / (3.0 * cam)
        length = (y_base - y_root) / (2.0 * hb)
        shear = shear + 1.2 * cam**2 / shear_modulus * length
        axial = axial + sam**2 / youngs * length
    hf, theta = foundation_parameters(gear, bore_radius)
    sf = 2.0 * rf * theta
    # u_f: from the root circle, along the centreline, to where the line of action crosses it.
    uf = yc - hc * np.tan(am) - rf
    tab = FOUNDATION_TABLE
    ratio = uf / sf
    foundation = (cam**2 / youngs) * (
        tab.value("L", hf, theta) * ratio**2
        + tab.value("M", hf, theta) * ratio
        + tab.value("P", hf, theta) * (1.0 + tab.value("Q", hf, theta) * np.tan(am) ** 2)
    )
    return {"bending": bending, "shear": shear, "axial": axial, "foundation": foundation}


def pair_compliance(pair: PairGeometry, materials, bores, s) -> dict[str, np.ndarray]:
    """Compliance per unit width (m^2/N) of one tooth pair touching at ``s`` on the path.

    ``s`` is measured from the driver's base tangent point along the transverse line of
    action; ``materials`` = ((E1, nu1), (E2, nu2)), ``bores`` = (r_int1, r_int2).
    Returns the Hertzian term, each tooth's four terms (``driver_bending`` ...) and ``total``.
    """
    s = np.asarray(s, dtype=float)
    (e1, nu1), (e2, nu2) = materials
    g1, g2 = pair.driver, pair.driven
    out = {"hertz": np.full_like(s, hertz_compliance(e1, nu1, e2, nu2))}
    one = tooth_compliance(g1, e1, nu1, bores[0], s / g1.base_radius)
    two = tooth_compliance(g2, e2, nu2, bores[1], (pair.line_of_action - s) / g2.base_radius)
    for key in one:
        out[f"driver_{key}"] = one[key]
        out[f"driven_{key}"] = two[key]
    out["total"] = sum(out.values())
    return out
