"""Results in the engineer's units: the model's non-dimensional numbers turned physical.

A model's coordinates are mesh deflections over the half backlash ``b``, its time is
``tau = omega_n t`` and its frequencies are over ``omega_n``; a mesh's dynamic force is
over ``k_m b``.  :class:`Units` holds the scales of one system with its values (the
generated ``scales()``, so a changed inertia or backlash moves them) and converts:

* a deflection (the dynamic transmission error) to um: ``x b 1e6``;
* a mesh force to N: ``F k_m b``; the dynamic factor is the largest force over the
  static one (no scale);
* a non-dimensional frequency to Hz (``w omega_n / 2 pi``), to rpm of the operating gear,
  and to orders of the reference mesh frequency (``w / omega``);
* a time to s (``tau / omega_n``).

``kind = "model"`` leaves every number as it is, with the model's words for the units, so
that one code path prints either.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

__all__ = ["UNITS", "Units"]

UNITS = ("model", "physical")


@dataclass(frozen=True)
class Units:
    """Conversions of one system's results (module docstring)."""

    kind: str
    scales: dict
    omega: float  # the system's non-dimensional excitation frequency

    @classmethod
    def of(cls, system, kind: str = "physical") -> Units:
        if kind not in UNITS:
            raise ValueError(f"units '{kind}': not one of {', '.join(UNITS)}")
        return cls(kind, system.scales(), system.omega)

    @property
    def physical(self) -> bool:
        return self.kind == "physical"

    def deflection(self, coordinate: str, x: float) -> float:
        """A deflection of ``coordinate``: um, or half backlashes."""
        b = self.scales["half_backlash_m"].get(coordinate)
        return x * b * 1e6 if self.physical and b is not None else x

    def deflection_unit(self, coordinate: str) -> str:
        physical = self.physical and coordinate in self.scales["half_backlash_m"]
        return "µm" if physical else "half backlashes"

    def force(self, coordinate: str, f: float) -> float:
        """A mesh force over ``k_m b``: N, or as it is."""
        k = self.scales.get("mean_stiffness_N_per_m", {}).get(coordinate)
        b = self.scales["half_backlash_m"].get(coordinate)
        return f * k * b if self.physical and k and b else f

    def force_unit(self, coordinate: str) -> str:
        k = self.scales.get("mean_stiffness_N_per_m", {}).get(coordinate)
        return "N" if self.physical and k else "k_m b"

    def frequency(self, w: float) -> float:
        """A non-dimensional frequency: Hz, or as it is."""
        return w * self.scales["omega_n_rad_per_s"] / (2 * math.pi) if self.physical else w

    @property
    def frequency_unit(self) -> str:
        return "Hz" if self.physical else "omega_n"

    def order(self, w: float) -> float:
        """A frequency as an order of the reference mesh frequency."""
        return w / self.omega

    def time(self, tau: float) -> float:
        return tau / self.scales["omega_n_rad_per_s"] if self.physical else tau

    @property
    def time_unit(self) -> str:
        return "s" if self.physical else "tau"

    def operating_point(self) -> str:
        """The speed and mesh frequency in words (physical), else omega."""
        s = self.scales
        if not self.physical or "speed_rpm" not in s:
            return f"omega = {self.omega:.6g}"
        return (
            f"{s['speed_rpm']:.6g} rpm of gear '{s.get('speed_gear', '?')}', mesh frequency "
            f"{s['mesh_frequency_hz']:.6g} Hz (omega = {self.omega:.6g})"
        )


def point_in_units(result, units: Units) -> dict:
    """One analysed point in ``units``: per mesh coordinate its deflection range (the
    dynamic transmission error), spectral peaks (frequency and order of the mesh
    frequency), the dynamic mesh force's range and the dynamic factor (largest force over
    the static one); and the operating point."""
    import numpy as np

    tr = result.trajectory
    system = tr.system
    out = {"units": units.kind, "operating_point": units.operating_point(), "coordinates": {}}
    ok = np.all(np.isfinite(tr.x), axis=0)
    forces = static = None
    mesh_force = getattr(system.module, "mesh_force", None)
    if mesh_force is not None and ok.any():
        forces = np.asarray(mesh_force(tr.t[ok], tr.x[:, ok], system.p), float)
        static = np.asarray(system.module.static_mesh_force(system.p), float)
    for k, c in enumerate(system.coordinates):
        u = tr.coordinate(c)
        u = u[np.isfinite(u)]
        row = {
            "deflection_unit": units.deflection_unit(c),
            "range": [units.deflection(c, float(u.min())), units.deflection(c, float(u.max()))]
            if u.size
            else None,
            "frequency_unit": units.frequency_unit,
            "peaks": [
                {"frequency": units.frequency(p["frequency"]), "order": p["per_omega"]}
                for p in result._spectrum(c).peaks()[:4]
            ],
        }
        if forces is not None and k < forces.shape[0]:
            f = forces[k]
            row["force_unit"] = units.force_unit(c)
            row["force_range"] = [units.force(c, float(f.min())), units.force(c, float(f.max()))]
            s = float(static[k]) if static is not None and k < static.size else 0.0
            row["static_force"] = units.force(c, s)
            row["dynamic_factor"] = float(np.max(np.abs(f)) / abs(s)) if s else None
        out["coordinates"][c] = row
    return out
