"""Tooth stiffness by ISO 6336-1 method B: single stiffness c' and mesh stiffness c_gamma.

ISO 6336-1:2019, "Calculation of load capacity of spur and helical gears -- Part 1: Basic
principles, introduction and general influence factors", clause 9 (method B):

* virtual teeth ``z_n = z / (cos^2(beta_b) cos(beta))``;
* ``q' = C1 + C2/z_n1 + C3/z_n2 + C4 x1 + C5 x1/z_n1 + C6 x2 + C7 x2/z_n2 + C8 x1^2 + C9 x2^2``
  (mm um / N), ``c'_th = 1 / q'``;
* for an internal pair (``derive/mesh/internal.py``) the ring counts as a rack:
  ``z_n2 = infinity`` (the ``C3`` and ``C7`` terms vanish), method B's rule for internal
  gears (the clause is not quoted here: check it against the edition in use), with ``x2``
  in the standard's sign (the opposite of this program's ring shift);
* ``c' = c'_th C_M C_R C_B cos(beta)`` with ``C_M = 0.8`` (solid discs), the gear blank factor
  ``C_R = 1 + ln(b_s/b) / (5 exp(s_R / (5 m_n)))`` (1 for solid discs; ``b_s/b`` within
  [0.2, 1.2], ``s_R / m_n >= 1``) and the basic rack factor ``C_B = (C_B1 + C_B2)/2``,
  ``C_Bi = [1 + 0.5 (1.2 - h_fPi/m_n)] [1 - 0.02 (20 deg - alpha_Pn)]``;
* below a line load ``F_t K_A / b`` of 100 N/mm, ``c'`` is multiplied by
  ``(F_t K_A / b / 100)^0.25``;
* for other materials than steel, ``c'`` is multiplied by ``E / E_st`` with
  ``E = 2 E1 E2 / (E1 + E2)``, ``E_st = 206000 N/mm^2``;
* ``c_gamma_alpha = c' (0.75 eps_alpha + 0.25)`` and ``c_gamma_beta = 0.85 c_gamma_alpha``
  (the optional reduction of up to 10 % for spur gears with ``eps_alpha < 1.2`` is not
  applied).

Stiffnesses are in N/(mm um), the unit of the standard; ``mesh_stiffness`` (N/m) is
``c_gamma_alpha b``, the figure to set against the potential-energy method's mean.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from .geometry import PairGeometry

__all__ = ["IsoStiffness", "Q_COEFFICIENTS", "iso_stiffness"]

#: C1..C9 of q' (ISO 6336-1:2019, method B).
Q_COEFFICIENTS = (
    0.04723,
    0.15551,
    0.25791,
    -0.00635,
    -0.11654,
    -0.00193,
    -0.24188,
    0.00529,
    0.00182,
)
_E_STEEL = 206000e6


@dataclass(frozen=True)
class IsoStiffness:
    """ISO 6336-1 method B stiffness figures of one pair (N/(mm um) unless stated)."""

    virtual_teeth: tuple[float, float]
    q_prime: float
    c_th: float
    c_m: float
    c_r: float
    c_b: float
    load_factor: float
    material_factor: float
    c_prime: float
    c_gamma_alpha: float
    c_gamma_beta: float
    face_width: float  # m

    @property
    def mesh_stiffness(self) -> float:
        """``c_gamma_alpha b`` in N/m."""
        return self.c_gamma_alpha * self.face_width * 1e3 * 1e6


def _blank_factor(rim_width_ratio: float | None, rim_thickness: float | None, mn: float) -> float:
    if rim_width_ratio is None:
        return 1.0
    ratio = min(max(rim_width_ratio, 0.2), 1.2)
    sr = max((rim_thickness or mn) / mn, 1.0)
    return 1.0 + math.log(ratio) / (5.0 * math.exp(sr / 5.0))


def iso_stiffness(
    pair: PairGeometry,
    *,
    dedendum: tuple[float, float] | None = None,
    rack_pressure_angle: float | None = None,
    c_m: float = 0.8,
    blank: tuple[tuple[float | None, float | None], tuple[float | None, float | None]] = (
        (None, None),
        (None, None),
    ),
    line_load: float | None = None,
    youngs: tuple[float, float] = (_E_STEEL, _E_STEEL),
) -> IsoStiffness:
    """ISO 6336-1 method B single and mesh stiffness of a pair (external, or a pinion and
    ring: module docstring).

    Parameters
    ----------
    pair : PairGeometry
    dedendum : (h_fP1/m_n, h_fP2/m_n)
        Basic-rack dedendum coefficients; default the gears' own.
    rack_pressure_angle : float
        ``alpha_Pn`` in rad; default the normal pressure angle.
    c_m : float
        Theoretical correction factor ``C_M`` (0.8 for solid discs).
    blank : ((b_s/b, s_R), (b_s/b, s_R)) per gear
        Web-to-face-width ratio and rim thickness (m) of a webbed blank; ``(None, None)``
        for a solid disc (``C_R = 1``).  ``C_R`` is the mean of the two gears' factors.
    line_load : float
        ``F_t K_A / b`` in N/mm; ``None`` for 100 N/mm or more (no reduction).
    youngs : (E1, E2)
        Young's moduli in Pa (the standard's figures are for steel, 206000 N/mm^2).
    """
    g1, g2 = pair.driver, pair.driven
    cb, beta = math.cos(g1.base_helix_angle), abs(g1.helix_angle)
    zn1 = g1.teeth / (cb**2 * math.cos(beta))
    zn2 = math.inf if g2.internal else g2.teeth / (cb**2 * math.cos(beta))
    x1, x2 = g1.profile_shift, -g2.profile_shift if g2.internal else g2.profile_shift
    c = Q_COEFFICIENTS
    q = (
        c[0]
        + c[1] / zn1
        + c[2] / zn2
        + c[3] * x1
        + c[4] * x1 / zn1
        + c[5] * x2
        + c[6] * x2 / zn2
        + c[7] * x1**2
        + c[8] * x2**2
    )
    c_th = 1.0 / q
    hf = dedendum or (g1.dedendum_coefficient, g2.dedendum_coefficient)
    alpha_p = math.degrees(
        g1.normal_pressure_angle if rack_pressure_angle is None else rack_pressure_angle
    )
    c_b = 0.5 * sum((1.0 + 0.5 * (1.2 - h)) * (1.0 - 0.02 * (20.0 - alpha_p)) for h in hf)
    mn = g1.normal_module
    c_r = 0.5 * sum(_blank_factor(ratio, rim, mn) for ratio, rim in blank)
    load = 1.0 if line_load is None or line_load >= 100.0 else (line_load / 100.0) ** 0.25
    e1, e2 = youngs
    material = (2.0 * e1 * e2 / (e1 + e2)) / _E_STEEL
    c_prime = c_th * c_m * c_r * c_b * math.cos(beta) * load * material
    eps = pair.transverse_contact_ratio
    c_ga = c_prime * (0.75 * eps + 0.25)
    return IsoStiffness(
        virtual_teeth=(zn1, zn2),
        q_prime=q,
        c_th=c_th,
        c_m=c_m,
        c_r=c_r,
        c_b=c_b,
        load_factor=load,
        material_factor=material,
        c_prime=c_prime,
        c_gamma_alpha=c_ga,
        c_gamma_beta=0.85 * c_ga,
        face_width=pair.face_width,
    )
