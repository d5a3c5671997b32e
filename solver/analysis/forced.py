"""The linear response of a gear set to its meshes' transmission errors, with their phases
(issue 26).

The linear model of a gear set (a ``STRUCTURE`` mapping: ``M`` diagonal, ``R``, the
springs' mean stiffnesses ``k_j``; ``solver.analysis.modes``), every spring a damper ``c_j =
2 zeta sqrt(k_j m_j)``, ``1 / m_j = r_j M^-1 r_j^T`` (as the nonlinear models take it), and
each mesh's transmission error ``e_j(t)`` excess material along its line of action, added
to its deflection as in the nonlinear model (``delta_j = r_j q + e_j``):

    ``M q'' + C q' + K q = - sum_j r_j^T (k_j e_j + c_j e_j')``.

One waveform per kind of mesh, delayed by the mesh's phase ``gamma_j`` (mesh periods, as its
stiffness variation is): ``e_j(t) = sum_l A_l cos(l Omega (t - gamma_j T) + phi_l) =
Re(E_jl e^{i l Omega t})``, ``E_jl = A_l e^{i (phi_l - 2 pi l gamma_j)}``, ``Omega`` the mesh
frequency (rad/s).

**Which modes a harmonic excites.**  With the flexible modes ``Phi`` normalised on ``M``,
harmonic ``l`` forces them through ``p_l = - Phi^T sum_j r_j^T k_j E_jl`` (the dampers add
``i l Omega c_j E_jl`` along the same rows).  A group of modes at one natural frequency is
excited where the norm of its block of ``p_l`` exceeds 1e-12 of ``p_l``'s largest entry,
else **suppressed by the phasing**: for ``N`` equally spaced planets and ``k = l Z_s mod
N``, only rotational modes for ``k = 0``, only translational modes for ``k = 1`` or ``N -
1``, and only planet modes otherwise (Parker, 2000, "A physical explanation for the
effectiveness of planet phasing to suppress planetary gear vibration").

**Response.**  ``Q_l = (K - (l Omega)^2 M + i l Omega C)^-1 F_l`` and each mesh's dynamic
force about its static value, ``(k_j + i l Omega c_j)(r_j Q_l + E_jl)``; its largest
magnitude over a mesh period from the harmonics summed on 64 samples.

**A turning carrier** (the structure's ``carrier_speed_rad_s``, ``G`` and ``K_Omega``):
``K`` becomes ``K - W^2 K_Omega`` and ``C`` becomes ``C + W G``.  The modes are then
complex (``modes.rotating_modes``): for ``lambda = i w`` the pencil ``lambda^2 M + lambda W G +
K' = K' - w^2 M + i w W G`` is Hermitian (``G`` real and skew), so a mode's left
eigenvector is its right one ``x`` and harmonic ``l`` forces it through ``x^H F_l``, ``x``
normalised to ``x^H M x = 1``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .frame import frame_terms, springs, stiffness
from .modes import rotating_modes
from .parametric import frequency_groups, modal_basis

__all__ = ["Errors", "excitation", "response"]


@dataclass(frozen=True)
class Errors:
    """The meshes' transmission errors: ``rows`` (their indices in ``R``), each one's phase
    in mesh periods, and its waveform ``((A_1, phi_1), ...)`` (m, rad; harmonic ``l`` at
    ``l - 1``)."""

    rows: tuple[int, ...]
    phases: tuple[float, ...]
    waveform: tuple[tuple[tuple[float, float], ...], ...]

    def __post_init__(self):
        if not len(self.rows) == len(self.phases) == len(self.waveform):
            raise ValueError("Errors: rows, phases and waveform need one entry per mesh")

    @property
    def harmonics(self) -> int:
        return max((len(w) for w in self.waveform), default=0)

    def amplitudes(self, l: int) -> np.ndarray:  # noqa: E741 (the harmonic, as papers write it)
        """``E_jl`` of every mesh (m, complex; zero where its waveform stops short of l)."""
        out = np.zeros(len(self.rows), dtype=complex)
        for i, (gamma, wave) in enumerate(zip(self.phases, self.waveform, strict=True)):
            if l <= len(wave):
                a, phi = wave[l - 1]
                out[i] = a * np.exp(1j * (phi - 2 * math.pi * l * gamma))
        return out


def _damping(structure: dict, zeta: float) -> np.ndarray:
    """``c_j = 2 zeta sqrt(k_j m_j)`` of every spring."""
    mass, R, k = springs(structure)
    m_j = 1.0 / np.einsum("ji,i,ji->j", R, 1.0 / mass, R)
    return 2.0 * zeta * np.sqrt(k * m_j)


def _flexible(structure: dict):
    """``(omega, X, R, k)``: the flexible modes (rad/s, ascending) and their shapes on
    ``M`` (real without a turning carrier, complex with one: module text)."""
    if not structure.get("carrier_speed_rad_s"):
        return modal_basis(structure)
    mass, R, k = springs(structure)
    f, shapes, rigid = rotating_modes(structure)
    X = shapes[:, ~rigid]
    X = X / np.sqrt(np.einsum("ij,i,ij->j", X.conj(), mass, X).real)
    return 2 * math.pi * f[~rigid], X, R, k


def excitation(structure: dict, errors: Errors, tolerance: float = 1e-7) -> list[dict]:
    """Per harmonic ``l`` and group of modes at one natural frequency (within
    ``tolerance`` of the largest, relative): ``harmonic``, ``modes`` (indices into the
    flexible modes), ``natural_rad_s``, ``force`` (the norm of the group's modal force,
    N/sqrt(kg), stiffness part) and ``excited`` (module text); in the order of ``l`` and
    then of the frequency."""
    omega, Phi, R, k = _flexible(structure)
    groups = frequency_groups(omega, tolerance)
    rows = np.asarray(errors.rows)
    out = []
    for l in range(1, errors.harmonics + 1):  # noqa: E741
        force = -(R[rows].T * k[rows]) @ errors.amplitudes(l)
        p = Phi.conj().T @ force
        floor = 1e-12 * np.abs(p).max(initial=0.0)
        for g in groups:
            size = float(np.linalg.norm(p[g]))
            out.append(
                {
                    "harmonic": l,
                    "modes": tuple(g),
                    "natural_rad_s": float(np.mean(omega[g])),
                    "force": size,
                    "excited": bool(size > floor),
                }
            )
    return out


def response(structure: dict, errors: Errors, zeta: float, Omegas) -> np.ndarray:
    """Each mesh's largest dynamic force (N, about its static value) over a mesh period at
    each mesh frequency of ``Omegas`` (rad/s): shape ``(len(Omegas), len(errors.rows))``."""
    mass, R, k = springs(structure)
    c = _damping(structure, zeta)
    M, K = np.diag(mass), stiffness(structure)
    C = R.T @ (c[:, None] * R) + frame_terms(structure)[1]
    rows = np.asarray(errors.rows)
    phase = np.exp(2j * math.pi * np.arange(64) / 64)
    out = np.zeros((len(Omegas), len(rows)))
    for i, Om in enumerate(np.asarray(Omegas, float)):
        signal = np.zeros((len(rows), 64))
        for l in range(1, errors.harmonics + 1):  # noqa: E741
            E = errors.amplitudes(l)
            s = 1j * l * Om
            spring = k[rows] + s * c[rows]
            Q = np.linalg.solve(K + s * C + s * s * M, -(R[rows].T * spring) @ E)
            force = spring * (R[rows] @ Q + E)
            signal += (force[:, None] * phase[None, :] ** l).real
        out[i] = np.abs(signal).max(axis=1)
    return out
