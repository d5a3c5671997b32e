"""The reference study's cases and the resolutions ``gearsym reproduce`` runs them at."""

from __future__ import annotations

from dataclasses import dataclass

__all__ = ["CASES", "DEAD_ZONE", "RESOLUTIONS", "TOLERANCES", "Resolution"]


@dataclass(frozen=True)
class Resolution:
    points: int  # lambda values in [0, 1]
    transient: int
    periods: int
    lyapunov_periods: int
    map_f1: tuple[float, ...]
    map_points: int


RESOLUTIONS = {
    "full": Resolution(51, 300, 100, 200, (0.1, 0.2, 0.3, 0.4, 0.5), 11),
    "quick": Resolution(11, 100, 32, 60, (0.1, 0.3, 0.5), 6),
}

CASES = (("light", "reference_light", 0.1), ("heavy", "reference_heavy", 0.5))
# the exact dead zone the polynomial approximates (the light scene; f1 set per case)
DEAD_ZONE = "reference_dead_zone"
TOLERANCES = {"rtol": 1e-8, "atol": 1e-10}
