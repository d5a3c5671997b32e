"""Natural frequencies and mode shapes of the linear, time-averaged model (issue 15).

The generated module's ``STRUCTURE`` gives the model in physical coordinates ``q``
(rotations, then translations): the diagonal mass matrix ``M`` and, for every coordinate
of the model (mesh deflections, shaft twists, translations), its row of ``R = d eta/d q``
and its spring at the mean stiffness.  With the backlash closed (the mesh in contact,
``g(u) = u``) and the mesh stiffness at its mean, ``K = R^T diag(k) R``, and the modes
solve ``K v = w^2 M v`` (``scipy.linalg.eigh``).  The rigid-body rotation is the mode with
``w = 0``.  No damping and no gyroscopic terms: the frequencies do not depend on speed, so
the resonance (Campbell) diagram is flat lines crossed by the mesh-frequency harmonics.
(A planetary set with a turning carrier is the exception: :func:`planetary_modes`.)

Each mode is labelled by where its kinetic energy sits, ``m_k v_k^2`` grouped into
rotations, translations across the axes and along them, and tilts: a group holding at
least :data:`DOMINANT` of it names the mode (``torsional``, ``translational``, ``axial``,
``tilting``), else it is ``coupled``.  The strain energy ``k_j (R v)_j^2`` of each spring
is given too.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import scipy.linalg

from .frame import frame_terms, springs, stiffness

__all__ = [
    "DOMINANT",
    "Mode",
    "Modes",
    "UnstableAtSpeed",
    "eigenproblem",
    "modes",
    "planetary_modes",
    "rotating_modes",
    "structure_modes",
]

DOMINANT = 0.8  # kinetic-energy share of one group that names a mode
_GROUPS = {
    "theta": "torsional",
    "u": "torsional",  # u = r theta: a body's rotation in a train with closed loops
    "x": "translational",
    "y": "translational",
    "z": "axial",
    "tx": "tilting",
    "ty": "tilting",
}


@dataclass(frozen=True)
class Mode:
    index: int
    frequency_hz: float
    label: str
    kinetic_shares: dict  # rotation / lateral / axial -> share of the kinetic energy
    strain_shares: dict  # spring (coordinate) -> share of the strain energy
    shape: dict  # physical coordinate -> amplitude (largest |amplitude| = 1)
    multiplicity: int = 1  # how many modes share this frequency (planetary sets)


@dataclass(frozen=True)
class Modes:
    model: str
    modes: tuple[Mode, ...]
    mesh_frequency_hz: float  # of the reference mesh at the scene's omega
    reference_teeth: int
    reference_driver: str = ""  # the first mesh's driver, whose speed the diagram uses

    @property
    def has_mesh_frequency(self) -> bool:
        """Whether the model states a mesh frequency (a planetary set's file does not)."""
        return math.isfinite(self.mesh_frequency_hz) and self.mesh_frequency_hz > 0

    def __repr__(self) -> str:
        elastic = [m for m in self.modes if m.label != "rigid-body"]
        first = f"; lowest {elastic[0].frequency_hz:.4g} Hz" if elastic else ""
        mesh = (
            f"; mesh frequency {self.mesh_frequency_hz:.4g} Hz" if self.has_mesh_frequency else ""
        )
        return (
            f"Modes({self.model}: {len(self.modes)} modes, "
            f"{len(self.modes) - len(elastic)} rigid-body{first}{mesh})"
        )

    def summary(self) -> str:
        """One line per mode (at most 12): frequency, over the mesh frequency where the
        model states one, its kind (and, of a planetary set, its multiplicity)."""
        lines = [
            f"modes of {self.model}; mesh frequency {self.mesh_frequency_hz:.6g} Hz "
            f"({self.reference_teeth} teeth of {self.reference_driver or 'the driver'})"
            if self.has_mesh_frequency
            else f"modes of {self.model} (no mesh frequency stated)"
        ]
        for m in self.modes[:12]:
            ratio = f" ({self.over_mesh(m):.3f} x mesh)" if self.has_mesh_frequency else ""
            times = f", x{m.multiplicity}" if m.multiplicity > 1 else ""
            lines.append(f"  {m.index}: {m.frequency_hz:10.4f} Hz{ratio}, {m.label}{times}")
        if len(self.modes) > 12:
            lines.append(f"  ... {len(self.modes) - 12} more")
        return "\n".join(lines)

    def over_mesh(self, mode: Mode) -> float | None:
        """The mode's frequency over the mesh frequency (None where none is stated)."""
        if not self.has_mesh_frequency:
            return None
        return mode.frequency_hz / self.mesh_frequency_hz

    def resonances(self, speeds_rpm: tuple[float, float], harmonics: int = 3) -> list[dict]:
        """Speeds of the reference driver where a mesh-frequency harmonic meets a mode:
        ``h z n / 60 = f`` (none without the reference driver's teeth: a planetary set's)."""
        out = []
        for mode in self.modes if self.reference_teeth > 0 else ():
            if mode.label == "rigid-body":
                continue
            for h in range(1, harmonics + 1):
                rpm = 60.0 * mode.frequency_hz / (h * self.reference_teeth)
                if speeds_rpm[0] <= rpm <= speeds_rpm[1]:
                    out.append({"mode": mode.index, "harmonic": h, "speed_rpm": rpm})
        return sorted(out, key=lambda r: r["speed_rpm"])

    def to_json(self, speeds_rpm: tuple[float, float] | None) -> dict:
        """The modes as JSON-ready values; without a mesh frequency (a planetary set, a
        train without its operating point) the ratio is None, and without speeds or the
        driver's teeth (a planetary set) the speed range and resonances are None and
        empty."""
        mesh = self.has_mesh_frequency
        speeds = bool(speeds_rpm) and self.reference_teeth > 0
        return {
            "model": self.model,
            "mesh_frequency_hz": self.mesh_frequency_hz if mesh else None,
            "reference_driver": self.reference_driver,
            "reference_teeth": self.reference_teeth,
            "modes": [
                {
                    "index": m.index,
                    "frequency_hz": m.frequency_hz,
                    "over_mesh_frequency": self.over_mesh(m),
                    "label": m.label,
                    "multiplicity": m.multiplicity,
                    "kinetic_shares": m.kinetic_shares,
                    "strain_shares": m.strain_shares,
                    "shape": m.shape,
                }
                for m in self.modes
            ],
            "speed_range_rpm": list(speeds_rpm) if speeds else None,
            "resonances": self.resonances(speeds_rpm) if speeds else [],
        }

    def to_dict(self, speeds_rpm: tuple[float, float] | None = None) -> dict:
        """:meth:`to_json` over ``speeds_rpm`` (default 0 to twice the scene's speed of
        the reference driver)."""
        if speeds_rpm is None and self.has_mesh_frequency:
            speeds_rpm = (0.0, 120.0 * self.mesh_frequency_hz / self.reference_teeth)
        return self.to_json(speeds_rpm)

    def to_table(self) -> tuple[list, list]:
        """One row per mode: index, frequency (Hz and over the mesh frequency), label."""
        columns = ["index", "frequency_hz", "over_mesh_frequency", "label"]
        return columns, [[m.index, m.frequency_hz, self.over_mesh(m), m.label] for m in self.modes]


def eigenproblem(structure: dict):
    """``(w2, vec, mass, R, k)``: the squared natural frequencies (ascending) and the mode
    shapes normalised on ``M`` of ``K v = w^2 M v``, ``K = R^T diag(k) R``, from a
    ``STRUCTURE`` mapping, with its ``M`` diagonal, ``R`` and ``k`` as arrays."""
    mass, R, k = springs(structure)
    w2, vec = scipy.linalg.eigh(R.T @ (k[:, None] * R), np.diag(mass))
    return w2, vec, mass, R, k


def modes(model, omega: float | None = None) -> Modes:
    """The modes of the linear, time-averaged model of ``model`` (a :class:`System` or a
    generated module; module docstring).  ``omega`` (the system's, else the scene's) sets
    the mesh frequency the modes are compared to."""
    module = getattr(model, "module", model)
    forcing = module.CONTRACT["forcing_frequency"]
    if omega is None and hasattr(model, "parameter"):
        omega = model.parameter(forcing)
    if omega is None:
        omega = module.DEFAULTS[module.PARAMETERS.index(forcing)]
    s = module.STRUCTURE
    return structure_modes(s, module.NAME, omega * s["omega_n"] / (2 * math.pi))


def structure_modes(s: dict, name: str, mesh_frequency_hz: float = float("nan")) -> Modes:
    """The modes of a ``STRUCTURE`` mapping (``M``'s diagonal, ``R``, ``k``, the
    coordinates' names and the reference mesh's driver and teeth): what :func:`modes`
    computes of a generated module, without one, for a model whose file states no operating
    point (a gear train without ``[train.dynamics]``: ``mesh_frequency_hz`` NaN, no ratio
    to it; the resonance speeds still follow from the teeth)."""
    w2, vec, mass, R, k = eigenproblem(s)
    # The rigid-body mode is zero up to round-off of the largest eigenvalue.
    rigid = np.abs(w2) <= 1e-10 * np.max(np.abs(w2))
    groups = [_GROUPS[n.split("_")[0]] for n in s["physical"]]
    out = []
    for i in range(len(w2)):
        v = vec[:, i]
        kinetic = mass * v**2
        shares = {
            g: float(
                sum(e for e, gg in zip(kinetic, groups, strict=True) if gg == g) / kinetic.sum()
            )
            for g in dict.fromkeys(groups)
        }
        strain = k * (R @ v) ** 2
        total = strain.sum()
        # A rigid-body mode strains nothing: its shares would be round-off normalised.
        strain_shares = {
            c: 0.0 if rigid[i] else float(e / total)
            for c, e in zip(s["coordinates"], strain, strict=True)
        }
        if rigid[i]:
            label = "rigid-body"
        else:
            top = max(shares, key=shares.get)
            label = top if shares[top] >= DOMINANT else "coupled"
        scale = v[np.argmax(np.abs(v))]
        out.append(
            Mode(
                index=i,
                frequency_hz=0.0 if rigid[i] else math.sqrt(w2[i]) / (2 * math.pi),
                label=label,
                kinetic_shares=shares,
                strain_shares=strain_shares,
                shape={n: float(a / scale) for n, a in zip(s["physical"], v, strict=True)},
            )
        )
    return Modes(
        name,
        tuple(out),
        float(mesh_frequency_hz),
        int(s["reference_teeth"]),
        str(s.get("reference_driver", "")),
    )


# A planetary set's modes (Lin and Parker 1999): a share of the kinetic energy below this
# (relative) counts as none when a mode is typed; frequencies closer than this (relative to
# the largest) are one repeated frequency.
PLANETARY_TOLERANCE = 1e-7


def planetary_modes(structure: dict, name: str) -> Modes:
    """The modes of a planetary set's linear model (``derive.equations.planetary``'s
    ``as_structure()``), each typed as Lin and Parker (1999) prove the modes of an equally
    spaced set are: **rotational** (the central members only turn), **translational** (they
    only translate), **planet** (they do not move: only the planets do), ``rigid-body``, or
    ``coupled`` where none holds (unequally spaced planets); and each with the number of
    modes at its frequency (translational modes come in pairs, planet modes N - 3 at a time,
    N - 1 in the torsional model).  No mesh frequency is known (the set's file gives no
    tooth-pass speed): ``mesh_frequency_hz`` is NaN.

    With a carrier speed (``carrier_speed_rad_s`` in ``structure``) the modes are those of
    ``M q'' + Omega_c G q' + (K - Omega_c^2 K_Omega) q = 0`` (:func:`rotating_modes`), their
    frequencies seen from the carrier and their shapes complex: ``shape`` then holds each
    coordinate's magnitude (the largest 1; a rigid-body mode, real, keeps its signs), the
    energies the magnitudes squared."""
    if structure.get("carrier_speed_rad_s"):
        mass, R, k = springs(structure)
        f, vec, rigid = rotating_modes(structure)
    else:
        w2, vec, mass, R, k = eigenproblem(structure)
        rigid = np.abs(w2) <= 1e-10 * np.max(np.abs(w2))
        f = np.where(rigid, 0.0, np.sqrt(np.abs(w2)) / (2 * math.pi))
    central = np.array([m in ("carrier", "ring", "sun") for m in structure["members"]])
    turning = np.array([m == "rotation" for m in structure["motions"]])
    tol = PLANETARY_TOLERANCE
    counts = [int(np.sum(np.abs(f - fi) <= tol * f.max())) for fi in f]
    out = []
    for i in range(len(f)):
        v = vec[:, i]
        kinetic = mass * np.abs(v) ** 2
        total = kinetic.sum()
        shares = {
            "central rotation": float(kinetic[central & turning].sum() / total),
            "central translation": float(kinetic[central & ~turning].sum() / total),
            "planets": float(kinetic[~central].sum() / total),
        }
        if rigid[i]:
            label = "rigid-body"
        elif shares["central rotation"] + shares["central translation"] <= tol:
            label = "planet"
        elif shares["central translation"] <= tol:
            label = "rotational"
        elif shares["central rotation"] <= tol:
            label = "translational"
        else:
            label = "coupled"
        strain = k * np.abs(R @ v) ** 2
        strain_total = strain.sum()
        strain_shares = {
            c: 0.0 if rigid[i] else float(e / strain_total)
            for c, e in zip(structure["coordinates"], strain, strict=True)
        }
        if np.iscomplexobj(v) and not np.any(v.imag):
            v = v.real  # a rigid-body mode of the turning set: real
        shape = np.abs(v) / np.abs(v).max() if np.iscomplexobj(v) else v / v[np.argmax(np.abs(v))]
        out.append(
            Mode(
                index=i,
                frequency_hz=float(f[i]),
                label=label,
                kinetic_shares=shares,
                strain_shares=strain_shares,
                shape={n: float(a) for n, a in zip(structure["physical"], shape, strict=True)},
                multiplicity=counts[i],
            )
        )
    return Modes(name, tuple(out), float("nan"), 0, "")


class UnstableAtSpeed(ValueError):
    """No modes are given at this carrier speed: the centripetal softening has made the
    stiffness indefinite (the set then diverges, or is at best held by its gyroscopic
    terms, which any damping turning with the carrier undoes: Kelvin, Tait and Chetaev's
    theorem).  With a positive definite stiffness every eigenvalue lies on the imaginary
    axis (the gyroscopic forces do no work); one found off it is a numerical failure and
    is refused too."""


def rotating_modes(structure: dict):
    """``(f, shapes, rigid)`` of ``M q'' + W G q' + (K - W^2 K_W) q = 0`` (``W`` the carrier
    speed): the rigid-body modes (the null space of the stiffness, real) first, then the
    ``n - r`` eigenvalues ``i 2 pi f`` of the first-order form with ``f > 0``, ascending,
    with the displacement part of their eigenvectors.  Raises :class:`UnstableAtSpeed` when
    the stiffness is indefinite or an eigenvalue leaves the imaginary axis (relative 1e-9;
    the rigid-body pairs, a Jordan block each, scatter by about 5e-9 and are set aside
    first)."""
    W = float(structure["carrier_speed_rad_s"])
    mass = springs(structure)[0]
    WG = frame_terms(structure)[1]
    K = stiffness(structure)
    n = mass.size
    w2, static = scipy.linalg.eigh(K, np.diag(mass))
    scale = np.max(np.abs(w2))
    rigid = np.abs(w2) <= 1e-10 * scale
    speed = f"{W * 60 / (2 * math.pi):g} rpm"
    if np.any(w2 < -1e-10 * scale):
        count = int(np.sum(w2 < -1e-10 * scale))
        held = (
            "it diverges"
            if count % 2
            else "it diverges or is at best held by its gyroscopic terms, which any damping "
            "turning with the carrier undoes"
        )
        raise UnstableAtSpeed(
            f"at a carrier speed of {speed} the centripetal terms make the stiffness "
            f"indefinite ({count} negative direction{'s' if count > 1 else ''}): {held}; no "
            "modes are given there"
        )
    A = np.zeros((2 * n, 2 * n))
    A[:n, n:] = np.eye(n)
    A[n:, :n] = -K / mass[:, None]
    A[n:, n:] = -WG / mass[:, None]
    lam, V = scipy.linalg.eig(A)
    size = np.max(np.abs(lam))
    # the 2 r eigenvalues nearest 0 are the rigid-body modes' (a Jordan block, scattered
    # by rounding to about sqrt(eps) of the largest): the rest must sit on the axis
    elastic = np.argsort(np.abs(lam))[2 * int(rigid.sum()) :]
    if np.max(np.abs(lam.real[elastic])) > 1e-9 * size:
        raise UnstableAtSpeed(
            f"at a carrier speed of {speed} an eigenvalue has a real part "
            f"{np.max(lam.real[elastic]):.3g} 1/s, which a positive definite stiffness "
            "excludes: the eigenvalues are not to be trusted there"
        )
    up = elastic[lam.imag[elastic] > 0]
    up = up[np.argsort(lam.imag[up])]
    if up.size != n - int(rigid.sum()):
        raise UnstableAtSpeed(
            f"at a carrier speed of {speed} the first-order form has {up.size} "
            f"oscillating eigenvalues where {n - int(rigid.sum())} were expected"
        )
    f = np.concatenate([np.zeros(int(rigid.sum())), lam.imag[up] / (2 * math.pi)])
    shapes = np.concatenate([static[:, rigid].astype(complex), V[:n, up]], axis=1)
    return f, shapes, np.arange(n) < int(rigid.sum())
