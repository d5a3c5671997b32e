"""Time-varying mesh stiffness by the potential-energy method, sliced for helical gears.

The compliance of one tooth pair per unit face width (bending, shear, axial compression,
fillet foundation and Hertzian contact) is ``derive/mesh/compliance.py``; this module
assembles it over the mesh cycle.

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
import warnings
from dataclasses import dataclass, field

import numpy as np
from scipy.interpolate import CubicSpline

from .compliance import (
    FOUNDATION_TABLE,
    SainsotTable,
    foundation_parameters,
    foundation_warnings,
    hertz_compliance,
    pair_compliance,
    tooth_compliance,
)
from .geometry import PairGeometry

# The compliance names are re-exported: callers import them from here.
__all__ = [
    "FOUNDATION_TABLE",
    "PemResult",
    "SainsotTable",
    "foundation_parameters",
    "foundation_warnings",
    "fourier_fit",
    "hertz_compliance",
    "pair_compliance",
    "pem_stiffness",
    "sliced_stiffness",
    "tooth_compliance",
    "tooth_pair_history",
]


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
