"""A planetary set as a topology file: sun, ring, carrier and N planets (issue 26).

A planetary set closes gear loops (each planet meshes with both the sun and the ring), so
it is not a tree of meshes and is not written with ``[[gear]]`` and ``[[mesh]]`` tables.
Its file has a ``[planetary]`` table instead, in the lumped-parameter terms of Lin and
Parker (1999, "Analytical characterization of the unique properties of planetary gear
free vibration"): each central member (sun, ring, carrier) has a mass, a rotational
inertia given as ``I / r^2`` on its displacement ``u = r theta`` (``r`` the base radius;
for the carrier the radius of the planets' centres), a translational bearing and a
torsional support; each planet sits on the carrier through a bearing; the sun-planet and
ring-planet meshes have a mean stiffness and a pressure angle; the planets' angles round
the carrier are equally spaced unless given.

    [topology]
    name = "lin-parker-1999-3"
    [planetary]
    degrees_of_freedom = "lateral-torsional"      # or "torsional"
    planets = 3                                   # or planet_angles_deg = [0, 120, 240]
    carrier_speed_rpm = 0                         # optional: the rotating frame's terms
    sun_teeth = 31                                # optional, both: the mesh phases
    ring_teeth = 89
    sun_planet = { stiffness_N_per_m = 5e8, pressure_angle_deg = 24.6 }
    ring_planet = { stiffness_N_per_m = 5e8, pressure_angle_deg = 24.6 }
    [planetary.sun]
    mass_kg = 0.4
    inertia_over_r2_kg = 0.39                     # or inertia_kg_m2 with radius_mm
    bearing_N_per_m = 1e8                         # translational (x and y)
    torsional_N_per_m = 0                         # on u = r theta; 0: free to turn
    ...
    [planetary.variation]                         # optional: gearsym modes --parametric
    sun_planet = { contact_ratio = 1.6, amplitude = 0.2 }   # needs sun_teeth, ring_teeth
    ring_planet = { contact_ratio = 1.8, amplitude = 0.2 }
    ring_sun_phase = 0.0                          # mesh periods, sun mesh to ring mesh
    harmonics = 3
    [planetary.dynamics]                          # optional: gearsym.planetary.dynamics
    sun_force_N = 2000                            # the sun's torque over its base radius
    sun_planet_half_backlash_um = 50              # each mesh's half backlash
    ring_planet_half_backlash_um = 50
    mesh_frequency_hz = 1000                      # the operating point (omega)
    damping_ratio = 0.03                          # every spring's, on its own mass
    # optional, each kind of mesh's (needs sun_teeth and ring_teeth: the meshes' phases)
    sun_planet_transmission_error = { amplitude_um = [2.0], phase_deg = [0.0] }
    ring_planet_transmission_error = { amplitude_um = [2.0], phase_deg = [0.0] }

The ``torsional`` model keeps each member's rotation only: translations are held and
each planet's centre moves with the carrier (its bearing rigid), as in the purely
torsional model Lin and Parker compare with.

``carrier_speed_rpm`` (default 0) turns the carrier at that constant speed: the translations
are then measured in the carrier's rotating frame, which adds the gyroscopic and
centripetal terms of Lin and Parker's equations of motion (their eq. 1); the modes are
then those of ``M q'' + Omega_c G q' + (K - Omega_c^2 K_Omega) q = 0``, their frequencies
seen from the carrier.  The torsional model has no translations for these terms to act
on and refuses a carrier speed; so do unbalanced planets (the carrier's static offset
under their net centripetal force is not modelled) and a speed at or above
``sqrt(k_p / m_p)``, where the bearings cannot hold the planets.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

from .reader import InputError, Table, load_toml

__all__ = [
    "DOFS",
    "Dynamics",
    "Member",
    "PlanetarySet",
    "Variation",
    "balanced",
    "bearing_limit_rpm",
    "imbalance",
    "is_planetary",
    "load_planetary",
    "needs_dynamics",
    "topology_file",
]

DOFS = ("torsional", "lateral-torsional")
CENTRAL = ("carrier", "ring", "sun")  # Lin and Parker's order of the central members


@dataclass(frozen=True)
class Member:
    """One body: its mass (kg), ``I / r^2`` (kg) and supports (N/m; a planet's bearing
    holds it on the carrier, a central member's bearing on the housing)."""

    name: str
    mass: float
    inertia_over_r2: float
    bearing: float
    torsional: float


@dataclass(frozen=True)
class Variation:
    """The meshes' stiffness variation about their mean, for the parametric instability
    (``gearsym modes --parametric``): each kind of mesh (sun-planet, ring-planet) a
    rectangular wave, one more tooth pair in contact during the fraction ``c - floor(c)``
    of each mesh period (``c`` the contact ratio), its stiffness then higher by
    ``amplitude`` times the mean; every mesh of a kind delayed by its phase, the ring
    meshes further by ``ring_sun_phase`` (mesh periods from a planet's sun mesh to its ring
    mesh: it follows from the teeth's geometry, not from the counts, and is given here);
    ``harmonics`` of each wave kept."""

    sun: tuple[float, float]  # (contact ratio, amplitude)
    ring: tuple[float, float]
    ring_sun_phase: float
    harmonics: int


@dataclass(frozen=True)
class Dynamics:
    """What the nonlinear model adds to the linear one (``[planetary.dynamics]``): the
    sun's load as a force on its base circle (its torque over its base radius; the
    carrier takes the reaction), each kind of mesh's half backlash (m), the mesh
    frequency of the operating point (Hz) and the damping ratio of every spring on its
    own equivalent mass."""

    sun_force: float
    backlash_sun: float
    backlash_ring: float
    mesh_frequency_hz: float
    damping_ratio: float
    # each kind of mesh's transmission error (a tree mesh's TransmissionError), or None
    error_sun: object = None
    error_ring: object = None


@dataclass(frozen=True)
class PlanetarySet:
    name: str
    description: str
    source: str
    dofs: str
    angles_deg: tuple[float, ...]  # each planet's angle round the carrier
    equally_spaced: bool
    members: dict  # carrier, ring, sun, planet -> Member
    k_sp: float  # sun-planet mean mesh stiffness, N/m
    k_rp: float  # ring-planet
    alpha_s_deg: float  # sun-planet pressure angle
    alpha_r_deg: float  # ring-planet
    sun_teeth: int | None = None  # tooth counts, for the mesh phases (optional)
    ring_teeth: int | None = None
    variation: Variation | None = None  # [planetary.variation] (optional)
    carrier_speed_rpm: float = 0.0  # the rotating frame's terms when not zero
    dynamics: Dynamics | None = None  # [planetary.dynamics] (optional)

    @property
    def planets(self) -> int:
        return len(self.angles_deg)


def is_planetary(path: Path | str) -> bool:
    """Whether the TOML file at ``path`` is a planetary set (a ``[planetary]`` table)."""
    path = Path(path)
    if path.suffix != ".toml" or not path.is_file():
        return False
    try:
        return "planetary" in load_toml(path)
    except InputError:
        return False


def _member(t: Table, name: str, planet: bool) -> Member:
    mass = t.number("mass_kg", low=0.0, low_open=True)
    if t.has("inertia_over_r2_kg") == t.has("inertia_kg_m2"):
        raise t.error(
            "inertia_over_r2_kg",
            "give exactly one of inertia_over_r2_kg (I / r^2 on u = r theta, kg) and "
            "inertia_kg_m2 with radius_mm (the base radius; the carrier: its planets' centres)",
        )
    if t.has("inertia_over_r2_kg"):
        j = t.number("inertia_over_r2_kg", low=0.0, low_open=True)
    else:
        inertia = t.number("inertia_kg_m2", low=0.0, low_open=True)
        radius = t.number("radius_mm", low=0.0, low_open=True) * 1e-3
        j = inertia / radius**2
    bearing = t.number("bearing_N_per_m", low=0.0)
    torsional = 0.0 if planet else t.number("torsional_N_per_m", low=0.0)
    t.finish()
    return Member(name, mass, j, bearing, torsional)


def _mesh(t: Table) -> tuple[float, float]:
    k = t.number("stiffness_N_per_m", low=0.0, low_open=True)
    alpha = t.number("pressure_angle_deg", low=0.0, high=60.0, low_open=True)
    t.finish()
    return k, alpha


def _variation(t: Table, teeth: bool) -> Variation:
    if not teeth:
        raise t.error(
            "sun_planet",
            "the stiffness variation needs sun_teeth and ring_teeth in [planetary] (each "
            "mesh's phase follows from them); add both",
        )
    waves = []
    for kind in ("sun_planet", "ring_planet"):
        w = t.table(kind)
        c = w.number("contact_ratio", low=1.0, high=10.0)
        amp = w.number("amplitude", low=0.0)
        w.finish()
        share = c - math.floor(c)
        if amp * share >= 1.0:
            raise w.error(
                "amplitude",
                f"{amp:g} at contact ratio {c:g} takes the stiffness to zero or below between "
                f"the extra pair's contacts (amplitude x {share:.3g} must stay below 1)",
            )
        waves.append((c, amp))
    phase = t.number("ring_sun_phase", 0.0, low=0.0, high=1.0, high_open=True)
    harmonics = t.integer("harmonics", 3, low=1, high=32)
    t.finish()
    return Variation(waves[0], waves[1], phase, harmonics)


def _dynamics(t: Table) -> Dynamics:
    force = t.number("sun_force_N", low=0.0, low_open=True)
    b_s = t.number("sun_planet_half_backlash_um", low=0.0, low_open=True) * 1e-6
    b_r = t.number("ring_planet_half_backlash_um", low=0.0, low_open=True) * 1e-6
    f_m = t.number("mesh_frequency_hz", low=0.0, low_open=True)
    zeta = t.number("damping_ratio", 0.03, low=0.0, high=1.0)
    errors = []
    for key in ("sun_planet_transmission_error", "ring_planet_transmission_error"):
        table = t.table(key, None)
        if table is None:
            errors.append(None)
            continue
        from .meshes import _transmission_error  # only where one is given: loading stays light

        errors.append(_transmission_error(table))
    t.finish()
    return Dynamics(force, b_s, b_r, f_m, zeta, *errors)


def imbalance(angles_deg) -> float:
    """The length of the sum of the planets' unit vectors (0: balanced)."""
    return abs(
        sum(complex(math.cos(math.radians(a)), math.sin(math.radians(a))) for a in angles_deg)
    )


def balanced(angles_deg) -> bool:
    """Whether planets at ``angles_deg`` balance (equally spaced, or in opposite pairs):
    a turning carrier needs it (the module text)."""
    return imbalance(angles_deg) <= 1e-9 * len(angles_deg)


def bearing_limit_rpm(planet: Member) -> float:
    """The carrier speed at which the planets' bearings can no longer hold them against
    the centripetal stiffness ``m_p Omega_c^2``: ``sqrt(k_p / m_p)``, in rpm."""
    return math.sqrt(planet.bearing / planet.mass) * 30.0 / math.pi


def topology_file(path: Path | str) -> tuple[Table, str, str]:
    """A topology file's top table, with its ``[topology]`` name and description read and
    checked (a planetary set's and a gear train's files begin alike)."""
    top = Table(load_toml(Path(path)), str(path))
    head = top.table("topology")
    name = head.target_name("name")
    description = head.string("description", "")
    head.finish()
    return top, name, description


def load_planetary(path: Path | str) -> PlanetarySet:
    """Read and check a planetary set's topology file (module docstring)."""
    source = str(path)
    top, name, description = topology_file(path)
    p = top.table("planetary")
    dofs = p.string("degrees_of_freedom", "lateral-torsional")
    if dofs not in DOFS:
        raise p.error("degrees_of_freedom", f"'{dofs}' is not one of {', '.join(DOFS)}")
    if p.has("planets") == p.has("planet_angles_deg"):
        raise p.error(
            "planets",
            "give exactly one of planets (that many, equally spaced) and planet_angles_deg",
        )
    if p.has("planets"):
        n = p.integer("planets", low=1, high=64)
        angles = tuple(360.0 * k / n for k in range(n))
        equal = True
    else:
        angles = p.numbers("planet_angles_deg")
        if not angles:
            raise p.error("planet_angles_deg", "give at least one planet angle")
        turn = sorted(a % 360.0 for a in angles)
        gaps = [b - a for a, b in zip(turn, turn[1:] + [turn[0] + 360.0], strict=True)]
        if min(gaps) <= 1e-9:
            raise p.error("planet_angles_deg", f"two planets at the same angle: {list(angles)}")
        equal = max(gaps) - min(gaps) <= 1e-9
    if p.has("sun_teeth") != p.has("ring_teeth"):
        raise p.error("sun_teeth", "give both sun_teeth and ring_teeth, or neither")
    z_s = p.integer("sun_teeth", None, low=3) if p.has("sun_teeth") else None
    z_r = p.integer("ring_teeth", None, low=3) if p.has("ring_teeth") else None
    if z_s is not None:
        if z_r <= z_s:
            raise p.error("ring_teeth", f"must exceed sun_teeth ({z_s}), got {z_r}")
        # Each planet must fit both the sun's and the ring's teeth where it sits: (Z_s +
        # Z_r) psi_n / 360 deg a whole number (equally spaced: (Z_s + Z_r) / N)
        for a in angles:
            turns = (z_s + z_r) * a / 360.0
            if abs(turns - round(turns)) > 1e-9:
                raise p.error(
                    "planet_angles_deg" if p.has("planet_angles_deg") else "planets",
                    f"a planet at {a:g} deg cannot mesh with both the sun ({z_s} teeth) and "
                    f"the ring ({z_r}): (sun_teeth + ring_teeth) x angle / 360 = {turns:g} "
                    "must be a whole number; change the angles or the tooth counts",
                )
    speed = p.number("carrier_speed_rpm", 0.0)
    if speed != 0.0 and dofs == "torsional":
        raise p.error(
            "carrier_speed_rpm",
            "the torsional model has no translations, on which the rotating frame's "
            'gyroscopic and centripetal terms act; use degrees_of_freedom = "lateral-'
            'torsional", or leave the carrier speed out',
        )
    if speed != 0.0 and not balanced(angles):
        balance = imbalance(angles)
        raise p.error(
            "carrier_speed_rpm",
            f"the planets at {[round(a, 6) for a in angles]} deg do not balance (the sum of "
            f"their unit vectors is {balance:.3g} long): a turning carrier would take a net "
            "centripetal force whose static offset this model leaves out; a carrier speed "
            "needs balanced planets (equally spaced, or in opposite pairs)",
        )
    k_sp, alpha_s = _mesh(p.table("sun_planet"))
    k_rp, alpha_r = _mesh(p.table("ring_planet"))
    members = {m: _member(p.table(m), m, False) for m in CENTRAL}
    members["planet"] = _member(p.table("planet"), "planet", True)
    planet = members["planet"]
    if speed != 0.0 and abs(speed) >= (limit := bearing_limit_rpm(planet)):
        raise p.error(
            "carrier_speed_rpm",
            f"{speed:g} rpm: the planets' bearings ({planet.bearing:g} N/m) cannot hold the "
            f"planets against the centripetal stiffness m_p Omega_c^2; keep it below "
            f"{limit:.6g} rpm or stiffen [planetary.planet] bearing_N_per_m",
        )
    variation = p.table("variation", None)
    variation = None if variation is None else _variation(variation, z_s is not None)
    dynamics = p.table("dynamics", None)
    dynamics = None if dynamics is None else _dynamics(dynamics)
    p.finish()
    top.finish()
    if any(not math.isfinite(a) for a in angles):
        raise InputError(source, "planetary.planet_angles_deg", "angles must be finite")
    return PlanetarySet(
        name,
        description,
        source,
        dofs,
        angles,
        equal,
        members,
        k_sp,
        k_rp,
        alpha_s,
        alpha_r,
        z_s,
        z_r,
        variation,
        speed,
        dynamics,
    )


def needs_dynamics(ps) -> None:
    """``InputError`` (one line) where the set's file cannot give the nonlinear model: no
    ``[planetary.dynamics]`` table."""
    if ps.dynamics is None:
        raise InputError(
            ps.source,
            "planetary.dynamics",
            "simulate, sweep, map, shoot, continue and frequency-response need the nonlinear "
            "model, and it needs a [planetary.dynamics] table (sun_force_N, the half "
            "backlashes, mesh_frequency_hz); add one (docs/user-guide.md, Planetary sets), or "
            "run `gearsym modes` on the set",
        )
