"""The linear, time-averaged model of a planetary set (issue 26, first the modes).

Coordinates after Lin and Parker (1999): each central member ``j`` (carrier ``c``, ring
``r``, sun ``s``) translates by ``x_j, y_j`` and turns by ``u_j = r_j theta_j`` (``r_j`` its
base radius; the carrier's the radius of the planets' centres); planet ``n`` at the angle
``psi_n`` round the carrier moves radially by ``zeta_n`` and tangentially by ``eta_n`` in the
carrier's frame and turns by ``u_n``.  All rotations are counted in one sense (the
torsional derivation's "one frame": an external mesh's deflection adds its gears' ``u``, an
internal one subtracts the ring's partner).

**The rotating frame** (``carrier_speed_rpm`` not zero, lateral-torsional model): the
translations are measured in axes turning with the carrier at the constant speed
``Omega_c`` (positive in the sense the rotations are counted), so a body of mass ``m`` at
``(x, y)`` in them feels ``m (x'' - 2 Omega_c y' - Omega_c^2 x)`` and ``m (y'' + 2 Omega_c x' -
Omega_c^2 y)``: Lin and Parker's ``M q'' + Omega_c G q' + (K - Omega_c^2 K_Omega) q``, with
``G`` holding ``-2 m`` at (x, y) and ``2 m`` at (y, x) of every body's pair of translations
(a planet's ``zeta``, ``eta``) and ``K_Omega`` holding ``m`` on each translation.  ``G`` is
skew, so the gyroscopic forces do no work.  Speed zero (the default) leaves both out, as
Lin and Parker's free-vibration analysis does.

One term is added to their ``K_Omega``, on the carrier's rotation ``u_c``.  A planet's
``eta`` is its tangential displacement in the frame (not relative to the carrier's
vibration), so turning the whole set moves every planet by ``eta`` about ``u_c``, and
``K_Omega`` alone prices that at ``-N m_p Omega_c^2 u_c^2 / 2``: the free set's rigid-body
rotation would diverge at any speed, which a rotation of the whole set cannot do.  What is
missing is the centripetal load that each planet's bearing carries in the steady state,
``F = k_p d = m_p Omega_c^2 (r_c + d)`` (``d`` its static stretch), working through the
pin's second-order motion ``r_c (1 - cos theta)``: ``+F u_c^2 / (2 r_c)`` a planet, with
``F / r_c = k_p m_p Omega_c^2 / (k_p - m_p Omega_c^2)`` (no ``r_c`` needed).  So
``K_Omega[u_c, u_c] = -N k_p m_p / (k_p - m_p Omega_c^2)``; the rest of the model keeps the
unstretched geometry.  With it the rigid-body rotation is an exact null vector at every
speed (tested: 0 Hz) for balanced planets (the sum of their unit vectors zero: equally
spaced, or in opposite pairs); the loader refuses a speed with unbalanced ones, whose net
centripetal force would offset the carrier.  The bearings carry the whole load where the
meshes take none of it (checked on the static deflection; true of the shipped sets);
where they would share it (for example every member held and unequal pressure angles)
the speed is refused, as the geometric stiffness of a mesh's preload is not modelled.  A
carrier speed at or above ``sqrt(k_p / m_p)`` (the bearings can no longer hold the
planets) is refused.  The term departs from Lin and Parker's ``K_Omega``, so results at
speed need not match work that used it alone; not checked against a published table at
speed (none was at hand).

**Springs** (each a row of ``R``, ``delta = R q``, and a stiffness ``k``):

* sun-planet mesh ``n``: its line of action leaves the sun at ``psi_n - alpha_s`` from the
  planet's radius (the direction ``d = (-sin(psi_n - alpha_s), cos(psi_n - alpha_s))``):
  ``delta_sn = d . (x_s, y_s) + u_s - d . (zeta_n e_r + eta_n e_t) + u_n``;
* ring-planet mesh ``n``, at ``psi_n + alpha_r``:
  ``delta_rn = d . (x_r, y_r) + u_r - d . (zeta_n e_r + eta_n e_t) - u_n``;
* planet ``n``'s bearing on the carrier, radial and tangential (the carrier's point under
  the planet's centre moves by ``(x_c, y_c) + u_c e_t``);
* each central member's bearing (``x_j``, ``y_j``) and torsional support (``u_j``), where
  their stiffness is not zero.

``e_r = (cos psi_n, sin psi_n)`` and ``e_t = (-sin psi_n, cos psi_n)``.  The projections are
worked out here by SymPy (``delta_sn`` becomes ``-x_s sin(psi_n - alpha_s) + y_s cos(psi_n -
alpha_s) + u_s - zeta_n sin alpha_s - eta_n cos alpha_s + u_n``: Lin and Parker's
sub-matrices ``K_s1, K_s2, K_s3`` are ``k_sp`` times the outer products of its
coefficients).

``M = diag(m, m, I / r^2)`` per body and ``K = R^T diag(k) R``.  The **torsional** model holds
every translation and carries each planet's centre with the carrier (``zeta_n = 0``,
``eta_n = u_c``): ``q = T q_t`` with ``q_t = (u_c, u_r, u_s, u_1, ..., u_N)``, ``M_t = T^T M T``
(the carrier's entry gains ``N m_p``) and ``R_t = R T``.

**Mesh phases** (with the tooth counts ``Z_s``, ``Z_r``; derived here from the teeth's
positions).  In the carrier's frame the sun's teeth pass the planets at ``Z_s |Omega_s -
Omega_c| / 2 pi`` per second, the mesh frequency; the sun's tooth that planet 1 sees now
reaches planet ``n`` after the sun has turned (relative to the carrier) by ``psi_n``, so the
stiffness of sun mesh ``n`` is that of mesh 1 delayed by ``gamma_sn = frac(Z_s psi_n / 2
pi)`` mesh periods, ``k_sn(t) = k_s1(t - gamma_sn T_m)``, with the angles counted in the
sense the sun turns relative to the carrier.  The ring turns the other way relative to the
carrier (Willis: ``(Omega_s - Omega_c) / (Omega_r - Omega_c) = -Z_r / Z_s``), so ``gamma_rn =
frac(-Z_r psi_n / 2 pi)``.  The sun meshes are in phase when ``Z_s psi_n / 2 pi`` is whole
(equally spaced: ``Z_s / N`` whole).  The phase between a planet's ring and sun meshes
depends on the tooth geometry (where each contact starts on its line of action), not on
the counts alone, and is not given.  The question is the one Parker and Lin (2004, "Mesh
phasing relationships in planetary and epicyclic gears") treat; the derivation here is
our own.

**Rigid-body modes**: the null space of ``R`` (its dimension found numerically, relative
tolerance 1e-10 of the largest singular value): a member free to turn with nothing
holding the set (``torsional_N_per_m = 0`` on all but one member) gives one.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import sympy as sp

from ..input.planetary import CENTRAL, PlanetarySet
from .body_dynamics import structure_mapping
from .planetary_frame import at_speed

__all__ = [
    "PlanetaryStructure",
    "derive_planetary",
    "mesh_phases",
    "planetary_meshes",
    "rectangular_wave",
]

_SHORT = {"carrier": "c", "ring": "r", "sun": "s"}


@dataclass(frozen=True)
class PlanetaryStructure:
    """The model of one planetary set: SymPy deflections and the numeric matrices in the
    form the modal analysis reads (``as_structure``)."""

    planetary: PlanetarySet
    physical: tuple[str, ...]  # q
    members: tuple[str, ...]  # the body of each entry of q: carrier, ring, sun, planet1, ...
    motions: tuple[str, ...]  # "translation" or "rotation" per entry of q
    mass: tuple[float, ...]  # M's diagonal
    springs: tuple[str, ...]  # the name of each row of R
    kinds: tuple[str, ...]  # "mesh", "planet bearing", "bearing", "torsional support"
    deflections: tuple[sp.Expr, ...]  # delta of each spring (lateral-torsional symbols)
    incidence: np.ndarray  # R (springs x q)
    stiffness: tuple[float, ...]
    rigid_body_modes: int
    phases: tuple[tuple[float, float], ...] | None = None  # (gamma_sn, gamma_rn) per planet
    carrier_speed_rad_s: float = 0.0  # Omega_c; not zero: G and K_Omega below
    gyroscopic: np.ndarray | None = None  # G (q x q), the coefficient of Omega_c q'
    centripetal: np.ndarray | None = None  # K_Omega (q x q), of -Omega_c^2 q

    def as_structure(self) -> dict:
        """The ``STRUCTURE`` mapping of a generated module (``solver.analysis.modes``)."""
        return {
            **structure_mapping(self, self.motions),
            **(
                {
                    "carrier_speed_rad_s": self.carrier_speed_rad_s,
                    "gyroscopic": tuple(tuple(map(float, r)) for r in self.gyroscopic),
                    "centripetal": tuple(tuple(map(float, r)) for r in self.centripetal),
                }
                if self.carrier_speed_rad_s
                else {}
            ),
        }


def _lateral(ps: PlanetarySet):
    """Symbols, deflections and stiffness of every spring of the lateral-torsional model."""
    q: list[sp.Symbol] = []
    members: list[str] = []
    motions: list[str] = []
    mass: list[float] = []
    sym = {}
    for j in CENTRAL:
        m = ps.members[j]
        s = _SHORT[j]
        for name, motion, value in (
            (f"x_{s}", "translation", m.mass),
            (f"y_{s}", "translation", m.mass),
            (f"u_{s}", "rotation", m.inertia_over_r2),
        ):
            sym[name] = sp.Symbol(name, real=True)
            q.append(sym[name])
            members.append(j)
            motions.append(motion)
            mass.append(value)
    p = ps.members["planet"]
    for n in range(1, ps.planets + 1):
        for name, motion, value in (
            (f"zeta_{n}", "translation", p.mass),
            (f"eta_{n}", "translation", p.mass),
            (f"u_{n}", "rotation", p.inertia_over_r2),
        ):
            sym[name] = sp.Symbol(name, real=True)
            q.append(sym[name])
            members.append(f"planet{n}")
            motions.append(motion)
            mass.append(value)

    alpha_s, alpha_r = sp.symbols("alpha_s alpha_r", real=True)
    numbers = {alpha_s: math.radians(ps.alpha_s_deg), alpha_r: math.radians(ps.alpha_r_deg)}
    springs, kinds, deflections, stiffness = [], [], [], []
    for n, angle in enumerate(ps.angles_deg, start=1):
        psi = sp.Symbol(f"psi_{n}", real=True)
        numbers[psi] = math.radians(angle)
        e_r = sp.Matrix([sp.cos(psi), sp.sin(psi)])
        e_t = sp.Matrix([-sp.sin(psi), sp.cos(psi)])
        planet = sym[f"zeta_{n}"] * e_r + sym[f"eta_{n}"] * e_t
        u_n = sym[f"u_{n}"]
        for mesh, centre, angle_loa, sense, k in (
            ("s", "s", psi - alpha_s, 1, ps.k_sp),
            ("r", "r", psi + alpha_r, -1, ps.k_rp),
        ):
            d = sp.Matrix([-sp.sin(angle_loa), sp.cos(angle_loa)])
            central = sp.Matrix([sym[f"x_{centre}"], sym[f"y_{centre}"]])
            delta = d.dot(central) + sym[f"u_{centre}"] - d.dot(planet) + sense * u_n
            springs.append(f"{mesh}p{n}")
            kinds.append("mesh")
            # each coordinate's coefficient in its simplest trigonometric form
            # (the planet's: sin and cos of the pressure angle alone)
            deflections.append(sum(sp.trigsimp(sp.diff(delta, v)) * v for v in q))
            stiffness.append(k)
        carrier = sp.Matrix([sym["x_c"], sym["y_c"]])
        for name, delta in (
            (f"bearing{n}_radial", e_r.dot(carrier) - sym[f"zeta_{n}"]),
            (f"bearing{n}_tangential", e_t.dot(carrier) + sym["u_c"] - sym[f"eta_{n}"]),
        ):
            springs.append(name)
            kinds.append("planet bearing")
            deflections.append(sp.expand(delta))
            stiffness.append(p.bearing)
    for j in CENTRAL:
        m, s = ps.members[j], _SHORT[j]
        for name, kind, k in (
            (f"x_{s}", "bearing", m.bearing),
            (f"y_{s}", "bearing", m.bearing),
            (f"u_{s}", "torsional support", m.torsional),
        ):
            if k > 0:
                springs.append(f"{kind.split()[0]}_{name}")
                kinds.append(kind)
                deflections.append(sym[name])
                stiffness.append(k)
    R = np.array(
        [[float(sp.diff(d, v).subs(numbers)) for v in q] for d in deflections], dtype=float
    )
    return q, members, motions, mass, springs, kinds, deflections, R, stiffness


def mesh_phases(ps: PlanetarySet) -> tuple[tuple[float, float], ...] | None:
    """``(gamma_sn, gamma_rn)`` of each planet in mesh periods, in [0, 1) (module
    docstring); None without tooth counts."""
    if ps.sun_teeth is None:
        return None

    def frac(x: float) -> float:
        g = x % 1.0
        return 0.0 if min(g, 1.0 - g) <= 1e-9 else g

    return tuple(
        (frac(ps.sun_teeth * a / 360.0), frac(-ps.ring_teeth * a / 360.0)) for a in ps.angles_deg
    )


def derive_planetary(ps: PlanetarySet) -> PlanetaryStructure:
    """The model of ``ps`` (module docstring)."""
    q, members, motions, mass, springs, kinds, deflections, R, k = _lateral(ps)
    names = [str(s) for s in q]
    if ps.dofs == "torsional":
        keep = ["u_c", "u_r", "u_s"] + [f"u_{n}" for n in range(1, ps.planets + 1)]
        T = np.zeros((len(names), len(keep)))
        for col, name in enumerate(keep):
            T[names.index(name), col] = 1.0
        for n in range(1, ps.planets + 1):  # each planet's centre carried by the carrier
            T[names.index(f"eta_{n}"), keep.index("u_c")] = 1.0
        M = T.T @ np.diag(mass) @ T
        R = R @ T
        live = [i for i in range(len(springs)) if np.any(np.abs(R[i]) > 1e-12)]
        springs = [springs[i] for i in live]
        kinds = [kinds[i] for i in live]
        deflections = [deflections[i] for i in live]
        k = [k[i] for i in live]
        R = R[live]
        members = [members[names.index(n)] for n in keep]
        motions = ["rotation"] * len(keep)
        mass = list(np.diag(M))
        names = keep
    sv = np.linalg.svd(R, compute_uv=False) if R.size else np.zeros(0)
    rank = int(np.sum(sv > 1e-10 * (sv.max() if sv.size else 1.0)))
    still = PlanetaryStructure(
        planetary=ps,
        physical=tuple(names),
        members=tuple(members),
        motions=tuple(motions),
        mass=tuple(float(v) for v in mass),
        springs=tuple(springs),
        kinds=tuple(kinds),
        deflections=tuple(deflections),
        incidence=R,
        stiffness=tuple(float(v) for v in k),
        rigid_body_modes=len(names) - rank,
        phases=mesh_phases(ps),
    )
    return at_speed(still, ps.carrier_speed_rpm) if ps.carrier_speed_rpm else still


def rectangular_wave(contact_ratio: float, amplitude: float, harmonics: int) -> tuple:
    """``((a_1, b_1), ...)``: the harmonics of ``k(t) / k_m - 1`` for a mesh with one more
    tooth pair in contact during the first fraction ``d = c - floor(c)`` of each mesh
    period, its stiffness then higher by ``amplitude`` times the mean (the rectangular
    waves of Lin and Parker, 2002): ``a_l = A sin(2 pi l d) / (pi l)``, ``b_l = A (1 -
    cos(2 pi l d)) / (pi l)``, in ``cos`` and ``sin`` of ``l`` times the mesh angle."""
    d = contact_ratio - math.floor(contact_ratio)
    return tuple(
        (
            amplitude * math.sin(2 * math.pi * h * d) / (math.pi * h),
            amplitude * (1.0 - math.cos(2 * math.pi * h * d)) / (math.pi * h),
        )
        for h in range(1, harmonics + 1)
    )


def planetary_meshes(st: PlanetaryStructure) -> tuple[tuple, tuple, tuple]:
    """``(rows, phases, waveforms)`` of the set's meshes for the parametric analysis
    (``solver.analysis.parametric.Meshes``): each mesh's row of ``R``, its phase in mesh
    periods (a ring mesh's further by ``ring_sun_phase``) and its rectangular wave.
    Needs the file's ``[planetary.variation]`` and tooth counts."""
    v = st.planetary.variation
    if v is None or st.phases is None:
        raise ValueError("the set's file has no [planetary.variation] with tooth counts")
    waves = {
        "s": rectangular_wave(*v.sun, v.harmonics),
        "r": rectangular_wave(*v.ring, v.harmonics),
    }
    rows, phases, waveforms = [], [], []
    for i, (name, kind) in enumerate(zip(st.springs, st.kinds, strict=True)):
        if kind != "mesh":
            continue
        sun_phase, ring_phase = st.phases[int(name[2:]) - 1]
        rows.append(i)
        phases.append(sun_phase if name[0] == "s" else (ring_phase + v.ring_sun_phase) % 1.0)
        waveforms.append(waves[name[0]])
    return tuple(rows), tuple(phases), tuple(waveforms)
