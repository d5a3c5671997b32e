"""Time-varying mesh stiffness by the potential-energy method, sliced for helical gears.

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
  ``derive/data/sainsot2004.toml``;

and, once per pair, the linearised Hertzian contact compliance of two cylinders of the
same length, ``1/k_h = 2 / (pi L E*)``, ``1/E* = (1-nu1^2)/E1 + (1-nu2^2)/E2`` (for equal
materials ``k_h = pi E L / (4 (1 - nu^2))``, Yang and Lin 1987).

Every term is a compliance inversely proportional to the loaded width ``L``; functions here
return compliances for unit width (m^2/N), which a slice of width ``dz`` divides by ``dz``.

A helical pair is cut into ``N`` transverse slices of width ``b/N``; the slice at axial
position ``z`` meets its tooth pair ``z tan(beta_b)`` further back on the path of contact,
so that at time ``tau`` (in mesh periods, counted from the entry of a tooth pair at the start
of active profile on the front face) tooth pair ``j`` touches slice ``z`` at

    s = s_A + (tau - j) p_bt - z tan(beta_b),     s_A <= s <= s_A + g_alpha,

``s`` measured from the driver's base tangent point.  All slices of all pairs in contact act
in parallel.  The sliced transverse stiffness ``k_t`` is turned into the stiffness along the
normal line of action that the equations of motion use by ``k = k_t / cos^2(beta_b)`` (the
normal force is ``F_t / cos(beta_b)``, the normal deflection ``delta_t cos(beta_b)``).
"""

from __future__ import annotations

import math
import tomllib
import warnings
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from scipy.interpolate import CubicSpline

from .geometry import GearGeometry, PairGeometry, involute

__all__ = [
    "FOUNDATION_TABLE",
    "PemResult",
    "SainsotTable",
    "fourier_fit",
    "hertz_compliance",
    "pair_compliance",
    "pem_stiffness",
    "sliced_stiffness",
    "tooth_compliance",
    "tooth_pair_history",
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


def _slices(pair: PairGeometry, slices: int):
    """Face width, base pitch, tan(beta_b) (either hand: same stiffness), start and length of
    the path of contact, slice width and the slices' mid positions."""
    dz = pair.face_width / slices
    return (
        pair.face_width,
        pair.transverse_base_pitch,
        math.tan(abs(pair.driver.base_helix_angle)),
        pair.start_of_contact,
        pair.path_of_contact,
        dz,
        (np.arange(slices) + 0.5) * dz,
    )


def sliced_stiffness(
    pair: PairGeometry, unit_stiffness, slices: int, samples: int
) -> tuple[np.ndarray, np.ndarray]:
    """``(tau, k_t(tau))``: sum over slices and tooth pairs of ``unit_stiffness(s) * b/N``.

    ``unit_stiffness`` maps positions on the path of contact to the stiffness per unit
    width of one tooth pair (N/m^2); ``tau`` covers one mesh period in ``samples`` points.
    """
    if slices < 1 or samples < 8:
        raise ValueError("need at least 1 slice and 8 samples per mesh period")
    b, pbt, tan_bb, s_a, g, dz, z = _slices(pair, slices)
    tau = np.arange(samples) / samples
    span = g + b * tan_bb  # a tooth pair is in contact somewhere for this long
    pairs = np.arange(-math.ceil(span / pbt) - 1, 2)
    k = np.zeros(samples)
    for j in pairs:
        s = s_a + (tau[:, None] - j) * pbt - z[None, :] * tan_bb
        inside = (s >= s_a) & (s < s_a + g)
        if inside.any():
            vals = np.zeros_like(s)
            vals[inside] = unit_stiffness(s[inside])
            k += vals.sum(axis=1) * dz
    return tau, k


def tooth_pair_history(
    pair: PairGeometry, unit_stiffness, slices: int, samples: int
) -> tuple[np.ndarray, np.ndarray]:
    """``(tau, k_t)`` of one tooth pair alone, from its entry on the front face
    (``tau = 0``) to its exit from the back face (``tau = eps_alpha + eps_beta``)."""
    b, pbt, tan_bb, s_a, g, dz, z = _slices(pair, slices)
    tau = np.linspace(0.0, (g + b * tan_bb) / pbt, samples)
    s = s_a + tau[:, None] * pbt - z[None, :] * tan_bb
    inside = (s >= s_a) & (s < s_a + g)
    vals = np.zeros_like(s)
    vals[inside] = unit_stiffness(s[inside])
    return tau, vals.sum(axis=1) * dz


def fourier_fit(k: np.ndarray, harmonics: int) -> tuple[float, np.ndarray, np.ndarray, float]:
    """Least-squares fit of uniform periodic samples by ``harmonics`` harmonics.

    Returns ``(mean, cos, sin, residual)`` with ``residual`` the RMS misfit over the mean.
    On a uniform grid the least-squares coefficients are the discrete Fourier coefficients.
    """
    n = len(k)
    if harmonics < 0 or 2 * harmonics >= n:
        raise ValueError(f"cannot fit {harmonics} harmonics to {n} samples")
    c = np.fft.rfft(k) / n
    mean = float(c[0].real)
    cos = 2.0 * c[1 : harmonics + 1].real
    sin = -2.0 * c[1 : harmonics + 1].imag
    tau = np.arange(n) / n
    fit = mean + sum(
        cos[h - 1] * np.cos(2 * np.pi * h * tau) + sin[h - 1] * np.sin(2 * np.pi * h * tau)
        for h in range(1, harmonics + 1)
    )
    residual = float(np.sqrt(np.mean((k - fit) ** 2)) / mean)
    return mean, cos, sin, residual


@dataclass(frozen=True)
class PemResult:
    """Mesh stiffness of one pair by the sliced potential-energy method (SI units).

    ``mean``, ``cos``, ``sin`` are along the normal line of action (what the equations of
    motion use); ``tau`` and ``k`` sample one mesh period; ``single_pair`` is the stiffness of
    one tooth pair over the whole face width against ``positions`` (m from ``T1``);
    ``components`` holds the pair's compliances per unit width at those positions.
    """

    pair: PairGeometry
    slices: int
    mean: float
    cos: tuple[float, ...]
    sin: tuple[float, ...]
    residual: float
    tau: np.ndarray = field(repr=False)
    k: np.ndarray = field(repr=False)
    positions: np.ndarray = field(repr=False)
    single_pair: np.ndarray = field(repr=False)
    components: dict = field(repr=False)
    warnings: tuple[str, ...] = ()
    unit_stiffness: object = field(default=None, repr=False, compare=False)

    def history(self, samples: int = 1024) -> tuple[np.ndarray, np.ndarray]:
        """One tooth pair's stiffness (normal direction, N/m) from entry to exit."""
        tau, k_t = tooth_pair_history(self.pair, self.unit_stiffness, self.slices, samples)
        return tau, k_t / math.cos(self.pair.driver.base_helix_angle) ** 2

    @property
    def transverse_mean(self) -> float:
        """Mean stiffness along the transverse line of action, ``k cos^2(beta_b)``."""
        return self.mean * math.cos(self.pair.driver.base_helix_angle) ** 2

    def ratios(self) -> tuple[float, ...]:
        """``|k_j| / k_m`` for each fitted harmonic."""
        return tuple(math.hypot(c, s) / self.mean for c, s in zip(self.cos, self.sin, strict=True))

    def fit(self, tau) -> np.ndarray:
        tau = np.asarray(tau, dtype=float)
        out = np.full_like(tau, self.mean)
        for h, (c, s) in enumerate(zip(self.cos, self.sin, strict=True), start=1):
            out += c * np.cos(2 * np.pi * h * tau) + s * np.sin(2 * np.pi * h * tau)
        return out


def pem_stiffness(
    pair: PairGeometry,
    materials,
    bores,
    *,
    slices: int = 200,
    harmonics: int = 3,
    samples: int = 2048,
    grid: int = 2001,
    names: tuple[str, str] = ("driver", "driven"),
) -> PemResult:
    """Mesh stiffness of an external pair by the sliced potential-energy method.

    Parameters
    ----------
    pair : PairGeometry
    materials : ((E1, nu1), (E2, nu2))
        Young's moduli (Pa) and Poisson's ratios of driver and driven.
    bores : (r_int1, r_int2)
        Bore radii (m) of the gear blanks, for the fillet-foundation term.
    slices : int
        Number of transverse slices ``N`` across the face width.
    harmonics : int
        Harmonics kept in the Fourier fit (3: ``km, k_j1, k_j2`` for j = 1..3).
    samples : int
        Samples of ``k`` per mesh period.
    grid : int
        Points on the path of contact at which the single-pair compliance is integrated;
        between them a cubic spline interpolates.
    """
    if not pair.face_width > 0.0:
        raise ValueError(f"face width must be > 0, got {pair.face_width}")
    for (e, nu), name in zip(materials, names, strict=True):
        if not (e > 0.0 and math.isfinite(e)) or not -1.0 < nu < 0.5:
            raise ValueError(
                f"{name}: Young's modulus must be > 0 and Poisson's ratio in (-1, 0.5), got "
                f"E = {e}, nu = {nu}"
            )
    if pair.start_of_contact <= 0.0 or pair.start_of_contact + pair.path_of_contact >= (
        pair.line_of_action
    ):
        raise ValueError(
            "the path of contact leaves the line of action between the base circles "
            "(involute interference); use more teeth or a positive profile shift"
        )
    for gear, name in zip((pair.driver, pair.driven), names, strict=True):
        if gear.tip_thickness <= 0.0:
            raise ValueError(f"{name}: pointed teeth (tip thickness <= 0)")
    found = []
    for gear, bore, name in zip((pair.driver, pair.driven), bores, names, strict=True):
        found += foundation_warnings(gear, bore, name)
    for message in found:
        warnings.warn(message, stacklevel=2)
    s_a, g = pair.start_of_contact, pair.path_of_contact
    positions = np.linspace(s_a, s_a + g, grid)
    comp = pair_compliance(pair, materials, bores, positions)
    bad = ~(np.isfinite(comp["total"]) & (comp["total"] > 0.0))
    if bad.any():
        raise ValueError(
            f"the tooth-pair compliance is not finite and positive at {int(bad.sum())} of "
            f"{grid} points of the path of contact; the geometry is outside the model's range"
        )
    spline = CubicSpline(positions, 1.0 / comp["total"])
    tau, k_t = sliced_stiffness(pair, spline, slices, samples)
    k = k_t / math.cos(pair.driver.base_helix_angle) ** 2
    mean, cos, sin, residual = fourier_fit(k, harmonics)
    return PemResult(
        pair=pair,
        slices=slices,
        mean=mean,
        cos=tuple(float(v) for v in cos),
        sin=tuple(float(v) for v in sin),
        residual=residual,
        tau=tau,
        k=k,
        positions=positions,
        single_pair=pair.face_width / comp["total"],
        components=comp,
        warnings=tuple(found),
        unit_stiffness=spline,
    )
