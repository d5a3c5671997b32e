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

``kind = "model"`` leaves every number as it is, in the model's words for the units.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

__all__ = [
    "UNITS",
    "Units",
    "orbit_in_units",
    "parameter_axis",
    "point_in_units",
]

UNITS = ("model", "physical")


@dataclass(frozen=True)
class Units:
    """Conversions of one system's results (module docstring)."""

    kind: str
    scales: dict
    omega: float  # the system's non-dimensional excitation frequency
    forcing: str = "omega"  # its name (the contract's forcing frequency)
    named: tuple = ()  # (name, unit) of the physical quantities a user sets by name

    @classmethod
    def of(cls, system, kind: str = "physical") -> Units:
        if kind not in UNITS:
            raise ValueError(f"units '{kind}': not one of {', '.join(UNITS)}")
        forcing = getattr(getattr(system, "contract", None), "forcing_frequency", "omega")
        return cls(kind, system.scales(), system.omega, forcing, _named(system.module))

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
        if not self.physical:
            return f"omega = {self.omega:.6g}"
        if "speed_rpm" not in s:  # a model in body coordinates states no speed
            return f"mesh frequency {self.frequency(self.omega):.6g} Hz (omega = {self.omega:.6g})"
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


# -- parameters, tables and figures in units ---------------------------------------------
SPEED, MESH_HZ = "speed_rpm", "mesh_frequency_hz"


def at(system, kind: str, values: dict) -> Units:
    """The units of ``system`` with ``values`` set (a swept backlash moves the µm per half
    backlash, a swept inertia omega_n); the system's own where a value is not one of its
    parameters (an open value: a model of its own, with the scales of the first)."""
    try:
        return Units.of(system.with_values(**values), kind)
    except (KeyError, ValueError):
        return Units.of(system, kind)


def along(system, kind: str, name: str, values) -> list[Units]:
    """:func:`at` for each value of the parameter ``name``."""
    return [at(system, kind, {name: float(v)}) for v in values]


def coordinate_of(units: Units, column: str) -> str | None:
    """The mesh coordinate whose deflection ``column`` holds (``u``, ``max_u``, ``min_u``;
    a frequency response's ``u_mean``, ``u_amplitude``, ``u_rms``, ``u_min``, ``u_max``),
    else None (velocities, dynamic factors and everything else stay as they are)."""
    for c in units.scales["half_backlash_m"]:
        if column in (c, f"max_{c}", f"min_{c}") or column in _RESPONSE.format(c=c).split():
            return c
    return None


_RESPONSE = "{c}_mean {c}_amplitude {c}_rms {c}_min {c}_max"  # frequency-response columns


def _named(module) -> tuple:
    """(name, unit) of each physical quantity of a generated module (``PHYSICAL``: name ->
    (value, unit, meaning)) and of its aliases; none that is a plain factor."""
    table = getattr(module, "PHYSICAL", {})
    units = {k: v[1] for k, v in table.items() if isinstance(v, tuple) and len(v) > 1}
    for alias, members in getattr(module, "PHYSICAL_ALIASES", {}).items():
        if members and members[0] in units:
            units[alias] = units[members[0]]
    shown = {"um": "µm", "deg": "°"}
    return tuple(
        (k, shown.get(u, u.replace("^2", "²"))) for k, u in units.items() if u not in ("", "1")
    )


def parameter_axis(units: Units, name: str):
    """How a figure shows the parameter ``name``: ``(label, top)``, ``top`` None or
    ``(label, forward, inverse)`` for a secondary axis.  Physical: omega stays the axis
    (the model's frequency) with the mesh frequency's scale in its label and the speed in
    rpm on top; the speed in rpm gets the mesh frequency in Hz on top.  Both are linear in
    the value: the speed is ``omega omega_n 30 / (z pi)`` (the audit page's closed form)."""
    s = units.scales
    unit = dict(units.named).get(name)  # a torque, a backlash: its unit in either kind
    plain = f"{name} ({unit})" if unit and name != SPEED else name
    if not units.physical or SPEED not in s or not s[SPEED] or not units.omega:
        return plain, None
    gear = s.get("speed_gear", "?")
    if name == units.forcing:
        k = s[SPEED] / units.omega
        hz = s["omega_n_rad_per_s"] / (2 * math.pi)
        label = f"{name} = mesh frequency / ω_n (1 is {hz:.5g} Hz)"
        return label, (f"speed of gear '{gear}' (rpm)", lambda w: w * k, lambda r: r / k)
    if name == SPEED:
        k = s[MESH_HZ] / s[SPEED]
        label = f"{name}: speed of gear '{gear}' (rpm)"
        return label, ("mesh frequency (Hz)", lambda r: r * k, lambda f: f / k)
    return plain, None


def secondary_axis(ax, top) -> None:
    """Draw ``top`` of :func:`parameter_axis` (if any) as the axes' top x axis."""
    if top is not None:
        label, forward, inverse = top
        ax.secondary_xaxis("top", functions=(forward, inverse)).set_xlabel(label, fontsize=8)


def state_unit(system, kind: str, state: str) -> str:
    """The unit a figure gives ``state`` in (:func:`state_factors`)."""
    if system is None:
        return "half backlashes"
    if state not in system.coordinates:
        return "half backlashes per unit τ" if state in system.states else ""
    return Units.of(system, kind).deflection_unit(state)


def state_factors(system, kind: str, name: str, values, state: str):
    """Per value of the parameter ``name``: the factor that turns ``state`` into ``kind``
    units (µm for a mesh deflection, with the half backlash at that value); and the unit
    (:func:`state_unit`).  Velocities stay in half backlashes per unit τ."""
    import numpy as np

    unit = state_unit(system, kind, state)
    if unit != "µm":
        return np.ones(len(values)), unit
    return np.array([u.deflection(state, 1.0) for u in along(system, kind, name, values)]), unit


def parameter_span(system, kind: str, name: str, values) -> str:
    """What a run over ``values`` of ``name`` covers in physical terms, e.g. ``omega 0.3 to
    1.2: gear 'p' at 634 to 2.54e+03 rpm, mesh frequency 528 to 2.11e+03 Hz``; "" in
    model units or for a model without a speed."""
    if kind != "physical" or not len(values):
        return ""
    ends = [at(system, kind, {name: float(v)}).scales for v in (min(values), max(values))]
    if SPEED not in ends[0]:
        return ""

    def g(x: float) -> str:  # 4 digits, 16000 not 1.6e+04
        text = f"{x:.4g}"
        return f"{x:.0f}" if "e+" in text and abs(x) < 1e9 else text

    def span(key: str) -> str:
        a, b = (float(e[key]) for e in ends)
        return g(a) if a == b else f"{g(a)} to {g(b)}"

    gear = ends[0].get("speed_gear", "?")
    lo, hi = min(values), max(values)
    shown = g(lo) if lo == hi else f"{g(lo)} to {g(hi)}"
    return f"{name} {shown}: gear '{gear}' at {span(SPEED)} rpm, mesh frequency {span(MESH_HZ)} Hz"


def poincare_range(system, kind: str, name: str, values, points, state: str) -> str:
    """The range of ``state``'s Poincaré values ``points`` (one array per value of
    ``name``) in ``kind`` units, e.g. ``[-12.1, 48.3] µm``; "" when there are none."""
    import numpy as np

    scale, unit = state_factors(system, kind, name, values, state)
    pts = [np.asarray(p, float).ravel() * k for p, k in zip(points, scale, strict=True)]
    pts = np.concatenate(pts) if pts else np.zeros(0)
    pts = pts[np.isfinite(pts)]
    return f"[{pts.min():.4g}, {pts.max():.4g}] {unit}" if pts.size else ""


def orbit_in_units(orbit, kind: str = "physical") -> dict:
    """A periodic orbit (``Orbit``) in ``kind`` units: the operating point, its period
    n T in s (``tau / omega_n``) and x0 of each mesh coordinate in µm (velocities stay
    in half backlashes per unit τ)."""
    system = orbit.system
    u = Units.of(system, kind)
    x0 = {c: u.deflection(c, float(orbit.x0[system.index(c)])) for c in system.coordinates}
    return {
        "units": kind,
        "operating_point": u.operating_point(),
        "period": u.time(orbit.period),
        "period_unit": u.time_unit,
        "x0": x0,
        "x0_unit": {c: u.deflection_unit(c) for c in system.coordinates},
    }


def orbit_line(block: dict) -> str:
    """:func:`orbit_in_units` in one printed line."""
    x0 = ", ".join(f"{c} = {v:.6g} {block['x0_unit'][c]}" for c, v in block["x0"].items())
    return (
        f"  {block['operating_point']}; period {block['period']:.6g} {block['period_unit']}; "
        f"x0: {x0}"
    )
