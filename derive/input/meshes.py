"""The meshes of a topology: one gear pair per ``[[mesh]]`` table, in SI units.

``parse_mesh`` reads one ``[[mesh]]`` table: its two gears, the pair geometry (ISO 21771,
``derive/mesh/geometry.py``) with its contact checks, the mesh coordinate's name, the half
backlash (``_um``), the stiffness (given harmonics, the contact-line model, or the sliced
potential-energy method of ``derive/mesh/pem.py``, or ISO 6336-1 method B's mean with the
contact-line waveform), the transmission error and the phase
lag against the first mesh (given, or from the layout).
"""

from __future__ import annotations

import math
import re
import warnings
from dataclasses import dataclass

from ..mesh.geometry import CentreDistanceError, PairGeometry
from ..mesh.internal import internal_pair_problem, mesh_pair
from ..mesh.iso6336 import iso_stiffness
from ..mesh.pem import pem_stiffness
from ..mesh.stiffness import MeshStiffness, contact_line_stiffness
from .gears import Gear
from .reader import Table, nearest
from .readings import ORIENTATIONS

__all__ = ["BACKLASH_NAME", "RESERVED_NAMES", "Mesh", "TransmissionError", "parse_mesh"]

# Names the generated code uses itself; coordinates may not take them.
RESERVED_NAMES = {"tau", "x", "p", "np", "ca", "omega", "out", "jac", "rhs"}
BACKLASH_NAME = re.compile(r"g[0-9]+")


@dataclass(frozen=True)
class TransmissionError:
    """Composite transmission error ``e(t) = sum_h a_h cos(h we t + phase_h)`` (m, rad)."""

    amplitudes: tuple[float, ...] = ()
    phases: tuple[float, ...] = ()


@dataclass(frozen=True)
class Mesh:
    """One gear pair.  ``driver`` pushes ``driven``; the coordinate is positive when the
    driver's working flanks are loaded (forward meshing), or, with ``orientation = -1``
    (``orientation = "reversed"``, see ``derive.readings``), measured the other way."""

    id: str
    driver: str
    driven: str
    coordinate: str
    half_backlash: float
    stiffness: MeshStiffness
    transmission_error: TransmissionError
    phase: float  # stiffness/TE phase lag relative to the reference mesh, rad
    phase_source: str
    pair: PairGeometry
    orientation: int = 1  # +1: coordinate positive on the driver's flank; -1: reversed
    # Angle of the driver's centre round the driven gear's, from +x, counter-clockwise seen
    # from +z (the axes' direction), rad: it sets the line of action's direction.
    driver_position: float = 0.0
    # (teeth of the gear shared with the reference mesh, angle in deg) when the phase comes
    # from the layout; the generated parameters() recomputes the phase from them
    # (derive/physical.py).
    layout_angle: tuple[int, float] | None = None


def parse_mesh(mt: Table, meshes: list[Mesh], by_id: dict[str, Gear]) -> Mesh:
    """One ``[[mesh]]`` table, checked against the gears ``by_id`` and the ``meshes``
    read before it (the first sets the time origin of the phases)."""
    mid = mt.identifier("id")
    ends = []
    for end in ("driver", "driven"):
        gid = mt.string(end)
        if gid not in by_id:
            raise mt.error(
                end,
                f"names unknown gear '{gid}'"
                + nearest(gid, by_id)
                + f"; gears: {', '.join(by_id)}",
            )
        ends.append(gid)
    if ends[0] == ends[1]:
        raise mt.error("driven", f"a gear cannot mesh with itself ('{ends[0]}')")
    g1, g2 = by_id[ends[0]], by_id[ends[1]]
    a_w = mt.number("centre_distance_mm", None, low=0, low_open=True)
    try:
        pair = mesh_pair(
            g1.geometry,
            g2.geometry,
            min(g1.face_width, g2.face_width),
            None if a_w is None else a_w * 1e-3,
        )
    except CentreDistanceError as err:
        raise mt.error("centre_distance_mm", str(err)) from None
    except ValueError as err:
        raise mt.error("driven", f"'{ends[0]}' and '{ends[1]}' cannot mesh: {err}") from None
    if pair.internal:
        problem = internal_pair_problem(pair, (ends[0], ends[1]))
        if problem:
            raise mt.error("driven", problem)
    else:
        _check_contact(mt, pair, ends)
    coordinate = mt.identifier("coordinate")
    if coordinate in RESERVED_NAMES or BACKLASH_NAME.fullmatch(coordinate):
        raise mt.error(
            "coordinate",
            f"'{coordinate}' is reserved; avoid {', '.join(sorted(RESERVED_NAMES))} "
            "and g1, g3, ...",
        )
    backlash = mt.number("half_backlash_um", low=0, low_open=True) * 1e-6
    stiffness = _stiffness(mt.table("stiffness"), pair, (g1, g2))
    te = _transmission_error(mt.table("transmission_error", None))
    phase, phase_source, layout = _phase(mt, meshes, ends, by_id)
    orientation = mt.string("orientation", "forward", choices=ORIENTATIONS)
    position = math.radians(mt.number("driver_position_deg", 0.0, low=-360.0, high=360.0))
    mt.finish()
    for other in meshes:
        if other.id == mid:
            raise mt.error("id", f"mesh '{mid}' is defined twice")
        if other.coordinate == coordinate:
            raise mt.error("coordinate", f"'{coordinate}' is already used by mesh '{other.id}'")
        if {other.driver, other.driven} == set(ends):
            raise mt.error(
                "driven", f"gears '{ends[0]}' and '{ends[1]}' already mesh in '{other.id}'"
            )
    return Mesh(
        mid,
        ends[0],
        ends[1],
        coordinate,
        backlash,
        stiffness,
        te,
        phase,
        phase_source,
        pair,
        ORIENTATIONS[orientation],
        position,
        layout,
    )


def _stiffness(t: Table, pair: PairGeometry, gears: tuple[Gear, Gear]) -> MeshStiffness:
    # An open value (derive/input/open_values.py): a factor on every harmonic, the mean kept.
    scale = t.number("harmonic_scale", 1.0, low=0.0)
    k = _stiffness_of(t, pair, gears)
    if scale == 1.0:
        return k
    return MeshStiffness(
        k.mean, tuple(scale * c for c in k.cos), tuple(scale * c for c in k.sin), k.source, scale
    )


def _stiffness_of(t: Table, pair: PairGeometry, gears: tuple[Gear, Gear]) -> MeshStiffness:
    source = t.string(
        "source", choices=("harmonics", "contact-line", "potential-energy", "iso-6336")
    )
    if source == "potential-energy":
        if pair.internal:
            raise t.error(
                "source",
                "the potential-energy method here is for external teeth; for a pinion and "
                'ring use "iso-6336", "contact-line" or "harmonics"',
            )
        return _pem_stiffness(t, pair, gears)
    if source == "iso-6336":
        return _iso_stiffness(t, pair, gears)
    # 1 kN/mm-scale plastics down to 1e3 N/m, steel's 1e8-1e10 N/m up to 1e13 N/m.
    mean = t.number("mean_N_per_m", low=1e3, high=1e13)
    if source == "harmonics":
        cos = t.numbers("cos_N_per_m", [])
        sin = t.numbers("sin_N_per_m", [])
        if len(cos) != len(sin):
            raise t.error("sin_N_per_m", f"needs as many entries as cos_N_per_m ({len(cos)})")
        t.finish()
        return MeshStiffness(mean, cos, sin, "harmonics")
    harmonics = t.integer("harmonics", 10, low=0, high=64)
    t.finish()
    return contact_line_stiffness(
        mean, pair.transverse_contact_ratio, pair.axial_contact_ratio, harmonics
    )


def _iso_stiffness(t: Table, pair: PairGeometry, gears: tuple[Gear, Gear]) -> MeshStiffness:
    """ISO 6336-1 method B mean stiffness ``c_gamma_alpha b`` (``derive/mesh/iso6336.py``;
    solid blanks, no low-load reduction) with the contact-line waveform of the pair's
    contact ratios (``derive/mesh/stiffness.py``: for spur teeth the rectangular
    single/double contact wave), rounded to 9 significant digits."""
    harmonics = t.integer("harmonics", 10, low=0, high=64)
    t.finish()
    iso = iso_stiffness(pair, youngs=tuple(g.material.youngs_modulus for g in gears))
    mean = float(f"{iso.mesh_stiffness:.9g}")
    wave = contact_line_stiffness(
        mean, pair.transverse_contact_ratio, pair.axial_contact_ratio, harmonics
    )
    return MeshStiffness(
        mean,
        tuple(float(f"{c:.9g}") for c in wave.cos),
        tuple(float(f"{c:.9g}") for c in wave.sin),
        "iso-6336",
    )


# The potential-energy results of this process, by everything they are computed from: a
# process that loads several variants of one scene (a map over open values, reproduce's
# sensitivity stage) parsed the same pairs again, 70 ms each.
_PEM_DONE: dict = {}


def _pem_stiffness(t: Table, pair: PairGeometry, gears: tuple[Gear, Gear]) -> MeshStiffness:
    """Sliced potential-energy stiffness (``derive/mesh/pem.py``); the Fourier coefficients are
    rounded to 9 significant digits so that generated files do not depend on the last bits
    of the FFT."""
    slices = t.integer("slices", 200, low=1, high=100000)
    harmonics = t.integer("harmonics", 10, low=0, high=64)
    samples = t.integer("samples", 2048, low=64, high=1 << 20)
    if 2 * harmonics >= samples:
        raise t.error("samples", f"needs more than {2 * harmonics} samples per mesh period")
    t.finish()
    for gear in gears:
        if gear.geometry.undercut:
            raise t.error(
                "source",
                f"gear '{gear.id}' is undercut; the potential-energy tooth model assumes a full "
                "involute -- raise its profile_shift or give the stiffness as harmonics",
            )
    key = (
        pair,
        tuple((g.material.youngs_modulus, g.material.poisson_ratio) for g in gears),
        tuple(g.bore_radius for g in gears),
        slices,
        harmonics,
        samples,
        tuple(g.id for g in gears),
    )
    if key not in _PEM_DONE:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            try:
                res = pem_stiffness(
                    pair,
                    key[1],
                    key[2],
                    slices=slices,
                    harmonics=harmonics,
                    samples=samples,
                    names=key[6],
                )
            except ValueError as err:
                raise t.error(
                    "source", f"the potential-energy method cannot be applied: {err}"
                ) from None
        _PEM_DONE[key] = (res, tuple(str(w.message) for w in caught))
    res, said = _PEM_DONE[key]
    for message in said:
        warnings.warn(f"{t.where('source')}: {message}", stacklevel=3)

    def r9(x: float) -> float:
        return float(f"{x:.9g}")

    return MeshStiffness(
        r9(res.mean),
        tuple(r9(c) for c in res.cos),
        tuple(r9(c) for c in res.sin),
        "potential-energy",
    )


def _check_contact(t: Table, pair: PairGeometry, ends: list[str]) -> None:
    """Involute contact must stay above both base circles, and the total contact ratio
    must reach 1 (for helical gears the overlap counts: eps_gamma = eps_alpha + eps_beta)."""
    approach = pair.approach_length
    recess = pair.path_of_contact - approach
    for length, gear, other in ((approach, ends[0], ends[1]), (recess, ends[1], ends[0])):
        base = pair.driver if gear == ends[0] else pair.driven
        available = base.base_radius * math.tan(pair.working_pressure_angle)
        if length > available * (1 + 1e-12):
            raise t.error(
                "driven",
                f"involute interference: the tip of '{other}' reaches below the base circle of "
                f"'{gear}' ({length * 1e3:.3f} mm of contact path against {available * 1e3:.3f} "
                "mm available); use more teeth or a positive profile shift",
            )
    for tip, root, a, b in (
        (pair.driver, pair.driven, ends[0], ends[1]),
        (pair.driven, pair.driver, ends[1], ends[0]),
    ):
        clearance = pair.centre_distance - tip.tip_radius - root.root_radius
        if clearance < 0.0:
            raise t.error(
                "driven",
                f"the tip of '{a}' runs {-clearance * 1e3:.3f} mm into the root circle of "
                f"'{b}' (negative tip clearance); lower the profile shifts or deepen the "
                "rack_dedendum",
            )
    (sap1, _), (sap2, _) = pair.active_radii
    for sap, geo, gear, other in (
        (sap1, pair.driver, ends[0], ends[1]),
        (sap2, pair.driven, ends[1], ends[0]),
    ):
        if sap < geo.form_radius * (1 - 1e-12):
            raise t.error(
                "driven",
                f"tip interference: the tip of '{other}' meets '{gear}' at radius "
                f"{sap * 1e3:.3f} mm, below its form circle ({geo.form_radius * 1e3:.3f} mm), "
                "in the fillet; use a positive profile shift on it or a smaller rack_root_radius",
            )
    if pair.total_contact_ratio < 1.0:
        raise t.error(
            "driven",
            f"total contact ratio {pair.total_contact_ratio:.3f} is below 1: the pair cannot "
            "transmit motion continuously",
        )


def _phase(t: Table, meshes: list, ends: list[str], by_id: dict) -> tuple:
    """Stiffness/transmission-error phase lag of a mesh relative to the first mesh, what it
    comes from, and (teeth of the shared gear, angle) when from the layout, else None.

    Either given (``stiffness_phase_deg``) or from the layout (``layout_angle_deg``): a mesh
    that shares a gear with the first mesh, in the same role (driver or driven in both),
    whose other centre lies an angle psi further round that gear in its direction of
    rotation, sees each tooth psi / w later -- a lag of z psi / 360 teeth, i.e.
    2 pi delta with delta the fractional part of z psi / 360 deg.
    """
    given, angle = t.has("stiffness_phase_deg"), t.has("layout_angle_deg")
    if not (given or angle):
        return 0.0, "reference" if not meshes else "none given", None
    if not meshes:
        raise t.error(
            "layout_angle_deg" if angle else "stiffness_phase_deg",
            "the first mesh sets the time origin and takes no phase; give phases on the "
            "other meshes",
        )
    if given and angle:
        raise t.error(
            "layout_angle_deg", "give either stiffness_phase_deg or layout_angle_deg, not both"
        )
    if given:
        return math.radians(t.number("stiffness_phase_deg")), "given", None
    psi = t.number("layout_angle_deg", low=-360.0, high=360.0)
    ref = meshes[0]
    common = sorted({ends[0], ends[1]} & {ref.driver, ref.driven})
    if not common:
        raise t.error(
            "layout_angle_deg",
            f"needs a mesh that shares a gear with the first mesh '{ref.id}'",
        )
    gear = common[0]
    role_ref = "driver" if ref.driver == gear else "driven"
    role_here = "driver" if ends[0] == gear else "driven"
    if role_ref != role_here:
        raise t.error(
            "layout_angle_deg",
            f"gear '{gear}' is the {role_ref} in mesh '{ref.id}' but the {role_here} here: "
            "opposite flanks carry the load, which this layout rule does not cover; give "
            "stiffness_phase_deg instead",
        )
    teeth = by_id[gear].teeth * psi / 360.0
    delta = teeth - math.floor(teeth)
    return (
        2.0 * math.pi * delta,
        f"layout: {psi:g} deg round gear '{gear}' spans {teeth:.4f} teeth, delta = {delta:.4f}",
        (by_id[gear].teeth, psi),
    )


def _transmission_error(t: Table | None) -> TransmissionError:
    if t is None:
        return TransmissionError()
    amps = t.numbers("amplitude_um", low=0.0)
    phases = t.numbers("phase_deg", [0.0] * len(amps), length=len(amps))
    t.finish()
    return TransmissionError(tuple(a * 1e-6 for a in amps), tuple(math.radians(p) for p in phases))
