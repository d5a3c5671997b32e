"""Time-varying mesh stiffness as a Fourier series over one mesh cycle (SI units).

``k(t) = km + sum_j [k_j1 cos(j we t) + k_j2 sin(j we t)]`` with ``we`` the mesh
frequency.  A :class:`MeshStiffness` holds ``km`` and the harmonic coefficients in N/m;
the derivation uses ``k(t) / km``.

Sources available here:

* ``harmonics`` -- coefficients given by the user;
* ``contact-line`` -- stiffness proportional to the total length of the contact lines,
  whose Fourier series has a closed form in the transverse and axial contact ratios
  (Maatar and Velex 1996, "An analytical expression for the time-varying contact length
  in perfect cylindrical gears: some possible applications in gear dynamics",
  J. Mech. Des. 118(4)):

  ``L(s)/L0 = 1 + sum_h 2 rho_h cos(2 pi h s - pi h (ea + eb))``,
  ``rho_h = sin(pi h ea) sin(pi h eb) / (pi^2 h^2 ea eb)``,

  with ``s`` the time in mesh periods, counted from the entry of a tooth pair at the
  start of active profile on the front face.  For ``eb -> 0`` (spur) the factor
  ``sin(pi h eb) / (pi h eb)`` tends to 1.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

__all__ = ["MeshStiffness", "contact_line_stiffness"]


@dataclass(frozen=True)
class MeshStiffness:
    """Mean stiffness and harmonics of one mesh, in N/m.

    Attributes
    ----------
    mean : float
        ``km`` (N/m), > 0.
    cos, sin : tuple of float
        ``k_j1`` and ``k_j2`` for j = 1..len (N/m).
    source : str
        Where the numbers come from (``harmonics``, ``contact-line``, ...).
    """

    mean: float
    cos: tuple[float, ...] = ()
    sin: tuple[float, ...] = ()
    source: str = "harmonics"
    harmonic_scale: float = 1.0  # the factor already applied to cos and sin (open value)

    def __post_init__(self):
        if not (self.mean > 0 and math.isfinite(self.mean)):
            raise ValueError(f"mean mesh stiffness must be > 0, got {self.mean}")
        if len(self.cos) != len(self.sin):
            raise ValueError("cos and sin harmonics need the same length")

    @property
    def harmonics(self) -> int:
        return len(self.cos)

    def normalised(self, harmonics: int) -> tuple[tuple[float, ...], tuple[float, ...]]:
        """``(k_j1 / km, k_j2 / km)`` for j = 1..harmonics (zeros past the given ones)."""
        pad = max(0, harmonics - self.harmonics)
        c = (tuple(x / self.mean for x in self.cos) + (0.0,) * pad)[:harmonics]
        s = (tuple(x / self.mean for x in self.sin) + (0.0,) * pad)[:harmonics]
        return c, s


def contact_line_stiffness(
    mean: float, transverse_ratio: float, axial_ratio: float, harmonics: int = 10
) -> MeshStiffness:
    """Stiffness proportional to the total contact-line length (closed-form series).

    Parameters
    ----------
    mean : float
        ``km`` in N/m.
    transverse_ratio, axial_ratio : float
        Transverse and axial (overlap) contact ratios ``ea`` and ``eb``.
    harmonics : int
        Number of harmonics to keep.
    """
    ea, eb = transverse_ratio, axial_ratio
    if ea <= 0 or eb < 0:
        raise ValueError("contact ratios must be positive")
    cos, sin = [], []
    for h in range(1, harmonics + 1):
        fa = math.sin(math.pi * h * ea) / (math.pi * h * ea)
        fb = 1.0 if eb == 0 else math.sin(math.pi * h * eb) / (math.pi * h * eb)
        rho = fa * fb
        phase = math.pi * h * (ea + eb)
        cos.append(2.0 * rho * math.cos(phase) * mean)
        sin.append(2.0 * rho * math.sin(phase) * mean)
    return MeshStiffness(mean=mean, cos=tuple(cos), sin=tuple(sin), source="contact-line")
