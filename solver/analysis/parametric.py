"""Parametric instability from the meshes' stiffness variation, with their phases (issue 26).

The linear model of a gear set (a ``STRUCTURE`` mapping: ``M``, ``R``, the springs' mean
stiffnesses; ``solver.analysis.modes``) with each mesh's stiffness varying about its mean,

    ``M q'' + (K_0 + sum_j k_j v_j(t) r_j r_j^T) q = 0``,

``r_j`` the mesh's row of ``R``, ``k_j`` its mean stiffness and ``v_j`` its relative variation,
one waveform for every mesh of a kind, delayed by the mesh's phase ``gamma_j`` (in mesh
periods ``T = 2 pi / Omega``, ``Omega`` the mesh frequency in rad/s):

    ``v_j(t) = sum_l a_l cos(l Omega (t - gamma_j T)) + b_l sin(l Omega (t - gamma_j T))``.

**First order.**  With the flexible modes ``Phi`` normalised on ``M`` (``Phi^T K_0 Phi =
diag(omega^2)``; a rigid-body mode is in the null space of every ``r_j`` and takes no part),
``v_j = sum_l c_jl e^{i l Omega t} + c.c.`` with ``c_jl = (a_l - i b_l) / 2 e^{-2 pi i l
gamma_j}``, and the modal excitation of harmonic ``l`` is

    ``G_l = sum_j k_j c_jl (Phi^T r_j)(Phi^T r_j)^T``  (complex symmetric).

By the method of multiple scales (our derivation; the form of the boundaries Lin and Parker,
2002, "Planetary gear parametric instability caused by mesh stiffness variation", give),
the **primary** instability of the modes at one natural frequency ``omega`` (one mode, or the
two of a translational pair) near ``l Omega = 2 omega`` is the band

    ``|l Omega - 2 omega| < s / omega``,

``s`` the largest singular value of the block of ``G_l`` on those modes (``|G_l,ii|`` for a
simple mode): write ``G_l``'s block by Takagi's factorisation ``U S U^T`` and the slow
amplitudes decouple into Mathieu equations, each unstable for ``|sigma| < s_k / omega``.  A
single degree of freedom gives Mathieu's ``delta = 1/4 +- epsilon / 2``.  Where the phases
make ``s`` vanish the instability is **suppressed** to first order: for equally spaced planets
a rotational mode's ``r_j . phi`` is the same at every planet, so ``G_l`` carries
``sum_n e^{-2 pi i l gamma_sn}``, which is zero unless ``l Z_s / N`` is whole.

**Floquet.**  :func:`multipliers` integrates the same equations over one mesh period in the
flexible modal coordinates (``scipy``'s DOP853 on the monodromy matrix) and returns its
eigenvalues; undamped, a stable set has them all on the unit circle.

**A turning carrier** (the structure's ``carrier_speed_rad_s``, ``gyroscopic`` ``G`` and
``centripetal`` ``K_W``): ``M q'' + W G q' + (K_0 - W^2 K_W + sum_j k_j v_j r_j r_j^T) q =
0``.  The modes are complex (``modes.rotating_modes``: ``(K' - w^2 M + i w W G) x = 0``);
``G`` skew makes ``x``'s conjugate the left eigenvector of the pencil, so the same multiple
scales (our derivation) project onto ``x^H`` and give the same bands with

    ``G_l = sum_j k_j c_jl (X^H r_j)(X^H r_j)^T``,  ``x^H (M - i W G / (2 w)) x = 1``,

the normalisation that makes the slow equations' ``x^H (2 w M - i W G) x`` equal to ``2 w``,
as ``Phi^T M Phi = 1`` does without the frame (``x^H G x`` is imaginary, so the norm is real,
and by the eigenproblem it is ``(x^H M x + x^H K' x / w^2) / 2 > 0``).  The turning splits
each translational pair, so its primary band becomes two, and their sum resonance a
combination band.  Within a group of modes at one frequency (a planet mode of five or
more planets stays multiple at speed) the shapes are made orthonormal in that form.  The
Floquet multipliers come from the equations in the body coordinates' first-order form over
one mesh period, restricted to the flexible modes' invariant subspace: the rigid-body
rotation, a Jordan block at 1, and its partner carry no mesh deflection, so the varying
meshes do not drive them (the restriction's residual is checked).  The carrier's speed is
the structure's: a band is of the mesh frequency at that speed, not of a speed that moves
with it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import scipy.integrate

from .frame import frame_terms, springs, stiffness
from .modes import eigenproblem, rotating_modes

__all__ = [
    "Instability",
    "Meshes",
    "combination_instabilities",
    "floquet_band",
    "frequency_groups",
    "holding",
    "modal_basis",
    "monodromy",
    "multipliers",
    "primary_instabilities",
    "unstable",
]


# modes whose frequencies differ by less than this (relative to the largest) are one group
_GROUPS = 1e-7


@dataclass(frozen=True)
class Meshes:
    """The varying springs: ``rows`` (their indices in ``R``), each one's phase in mesh
    periods, and its waveform's ``a_l`` and ``b_l`` (``waveform[j] = ((a_1, b_1), ...)``,
    relative to the mean stiffness)."""

    rows: tuple[int, ...]
    phases: tuple[float, ...]
    waveform: tuple[tuple[tuple[float, float], ...], ...]

    def __post_init__(self):
        if not len(self.rows) == len(self.phases) == len(self.waveform):
            raise ValueError("Meshes: rows, phases and waveform need one entry per mesh")


@dataclass(frozen=True)
class Instability:
    """The first-order band of one instability: ``modes`` (indices into the flexible
    modes), the harmonic ``l``, their natural frequency ``omega`` (rad/s), ``s``
    (rad^2/s^2) and the band of the mesh frequency ``Omega`` in rad/s, ``lower`` to
    ``upper`` (equal where suppressed).  A combination instability has a second group of
    modes, ``partner``, at ``omega_partner``."""

    modes: tuple[int, ...]
    l: int  # noqa: E741 (the harmonic, as the papers write it)
    omega: float
    s: float
    lower: float
    upper: float
    partner: tuple[int, ...] = ()
    omega_partner: float | None = None

    @property
    def centre(self) -> float:
        other = self.omega if self.omega_partner is None else self.omega_partner
        return (self.omega + other) / self.l

    @property
    def kind(self) -> str:
        return "combination" if self.partner else "primary"

    @property
    def suppressed(self) -> bool:
        return self.upper == self.lower


def modal_basis(structure: dict, rigid_tolerance: float = 1e-10):
    """``(omega, Phi, R, k)``: the flexible modes' frequencies (rad/s, ascending) and
    shapes normalised on ``M`` (``modes.eigenproblem``), ``R`` and ``k``; with a turning
    carrier the complex shapes of ``modes.rotating_modes`` normalised as the module text
    says (``UnstableAtSpeed`` where the set cannot run at its speed)."""
    if not structure.get("carrier_speed_rad_s"):
        w2, vec, _, R, k = eigenproblem(structure)
        flexible = w2 > rigid_tolerance * np.max(np.abs(w2))
        return np.sqrt(w2[flexible]), vec[:, flexible], R, k
    mass, R, k = springs(structure)
    f, shapes, rigid = rotating_modes(structure)
    omega, X = 2 * math.pi * f[~rigid], shapes[:, ~rigid].copy()
    WG = frame_terms(structure)[1]
    # Within a group of modes at one frequency (a planet mode of five planets stays double
    # at speed) the eigensolver's basis is any: orthonormal in N = M - i W G / (2 w), as
    # the slow equations take it, by N's Cholesky factor.  N is Hermitian and, on the
    # modes, positive: x^H N x = (x^H M x + x^H K' x / w^2) / 2 with K' positive
    # semi-definite where rotating_modes gives modes at all.
    for g in frequency_groups(omega, _GROUPS):
        N = X[:, g].conj().T @ (np.diag(mass) - 0.5j / np.mean(omega[g]) * WG) @ X[:, g]
        L = np.linalg.cholesky(0.5 * (N + N.conj().T))
        X[:, g] = np.linalg.solve(L.conj(), X[:, g].T).T
    return omega, X, R, k


def _excitation(basis: tuple, meshes: Meshes, l: int) -> np.ndarray:  # noqa: E741
    """``G_l`` on the flexible modes of ``basis`` (:func:`modal_basis`; module text)."""
    _, Phi, R, k = basis
    G = np.zeros((Phi.shape[1], Phi.shape[1]), dtype=complex)
    for row, gamma, wave in zip(meshes.rows, meshes.phases, meshes.waveform, strict=True):
        if l > len(wave):
            continue
        a, b = wave[l - 1]
        c = 0.5 * (a - 1j * b) * np.exp(-2j * math.pi * l * gamma)
        p = Phi.conj().T @ R[row]
        G += k[row] * c * np.outer(p, p)
    return G


def frequency_groups(omega: np.ndarray, tolerance: float) -> list[list[int]]:
    """Indices of the modes at one frequency (within ``tolerance`` of the largest)."""
    groups: list[list[int]] = []
    for i, w in enumerate(omega):
        if groups and abs(w - omega[groups[-1][0]]) <= tolerance * omega[-1]:
            groups[-1].append(i)
        else:
            groups.append([i])
    return groups


def _largest(block: np.ndarray, G: np.ndarray) -> float:
    """The largest singular value of ``block``, 0 below 1e-12 of ``G``'s largest entry
    (what the phases cancel is zero to rounding)."""
    s = float(np.linalg.svd(block, compute_uv=False).max())
    return 0.0 if s <= 1e-12 * np.abs(G).max(initial=0.0) else s


def primary_instabilities(
    structure: dict, meshes: Meshes, harmonics: int, group_tolerance: float = _GROUPS
) -> list[Instability]:
    """The first-order band of every primary instability ``l Omega = 2 omega``, ``l = 1 ..
    harmonics``, modes within ``group_tolerance`` (relative) of one frequency taken
    together (module text), in the order of ``l`` and then of ``omega``."""
    basis = modal_basis(structure)
    omega = basis[0]
    out = []
    for h in range(1, harmonics + 1):
        G = _excitation(basis, meshes, h)
        for g in frequency_groups(omega, group_tolerance):
            w = float(np.mean(omega[g]))
            s = _largest(G[np.ix_(g, g)], G)
            out.append(Instability(tuple(g), h, w, s, (2 * w - s / w) / h, (2 * w + s / w) / h))
    return out


def combination_instabilities(
    structure: dict, meshes: Meshes, harmonics: int, group_tolerance: float = _GROUPS
) -> list[Instability]:
    """The first-order band of every combination instability of the sum type, ``l Omega
    = omega_1 + omega_2`` for two groups of modes at different frequencies:

        ``|l Omega - omega_1 - omega_2| < s / sqrt(omega_1 omega_2)``,

    ``s`` the largest singular value of ``G_l``'s block coupling the two groups (the
    singular value decomposition of the block decouples the slow amplitudes into pairs,
    each unstable there; a group with itself is the primary band).  The difference type
    ``omega_2 - omega_1`` is not unstable in this undamped, symmetric model.  In the order
    of ``l``, then of the first group, then of the second."""
    basis = modal_basis(structure)
    omega = basis[0]
    groups = frequency_groups(omega, group_tolerance)
    out = []
    for h in range(1, harmonics + 1):
        G = _excitation(basis, meshes, h)
        for a, ga in enumerate(groups):
            for gb in groups[a + 1 :]:
                w1, w2 = float(np.mean(omega[ga])), float(np.mean(omega[gb]))
                s = _largest(G[np.ix_(ga, gb)], G)
                half = s / math.sqrt(w1 * w2) / h
                centre = (w1 + w2) / h
                out.append(
                    Instability(tuple(ga), h, w1, s, centre - half, centre + half, tuple(gb), w2)
                )
    return out


def multipliers(
    structure: dict, meshes: Meshes, Omega: float, *, rtol: float = 1e-11
) -> np.ndarray:
    """The Floquet multipliers of the set at the mesh frequency ``Omega`` (rad/s): the
    eigenvalues of :func:`monodromy`."""
    return np.linalg.eigvals(monodromy(structure, meshes, Omega, rtol=rtol))


def monodromy(structure: dict, meshes: Meshes, Omega: float, *, rtol: float = 1e-11) -> np.ndarray:
    """The monodromy matrix over one mesh period at the mesh frequency ``Omega`` (rad/s),
    ``(2n, 2n)`` in the flexible modal coordinates ``(eta, d eta / d(Omega t))``, by DOP853
    at ``rtol``; the energy ``(|eta'|^2 Omega^2 + sum omega_i^2 eta_i^2) / 2`` of the
    undamped set with constant stiffness is its invariant.  With a turning carrier, the
    map on the flexible modes' invariant subspace (module text): complex, ``(2m, 2m)`` for
    ``m`` flexible modes, in the coordinates of their first-order eigenvectors."""
    if structure.get("carrier_speed_rad_s"):
        return _turning_monodromy(structure, meshes, Omega, rtol)
    omega, Phi, R, k = modal_basis(structure)
    n = omega.size
    P = np.array([Phi.T @ R[row] for row in meshes.rows])  # (meshes, n)
    weights = np.array([k[row] for row in meshes.rows])

    v = _waves(meshes)

    # in the mesh's angle s = Omega t (one period is 2 pi), so that eta and its
    # derivative are of one size
    def rhs(s: float, y: np.ndarray) -> np.ndarray:
        X = y.reshape(2 * n, 2 * n)
        stiff = (np.diag(omega**2) + P.T @ ((weights * v(s))[:, None] * P)) / Omega**2
        return np.vstack([X[n:], -stiff @ X[:n]]).ravel()

    return _integrated(rhs, 2 * n, rtol)


def _turning_monodromy(structure: dict, meshes: Meshes, Omega: float, rtol: float) -> np.ndarray:
    """:func:`monodromy` of a set with a turning carrier: the body coordinates ``q`` and
    ``dq / d(Omega t)`` over one mesh period, then the flexible subspace's map ``A`` with
    ``Phi V = V A`` (``V`` its first-order eigenvectors; exact, the subspace being invariant)."""
    mass, R, k = springs(structure)
    n = mass.size
    WG = frame_terms(structure)[1]
    K = stiffness(structure)
    f, shapes, rigid = rotating_modes(structure)
    X, lam = shapes[:, ~rigid], 2j * math.pi * f[~rigid] / Omega
    V = np.block([[X, X.conj()], [X * lam, (X * lam).conj()]])
    rows = np.array([R[row] for row in meshes.rows])
    weights = np.array([k[row] for row in meshes.rows])
    wave = _waves(meshes)

    def rhs(s: float, y: np.ndarray) -> np.ndarray:
        Y = y.reshape(2 * n, 2 * n)
        stiff = K + rows.T @ ((weights * wave(s))[:, None] * rows)
        accel = -(stiff @ Y[:n] / Omega + WG @ Y[n:]) / (Omega * mass[:, None])
        return np.vstack([Y[n:], accel]).ravel()

    Phi = _integrated(rhs, 2 * n, rtol)
    A = np.linalg.lstsq(V, Phi @ V, rcond=None)[0]
    # exact where the subspace is invariant: the rigid rotation and its Jordan partner
    # (K' a = -W G u) carry no mesh deflection, so the varying meshes do not drive them
    # (true of the planetary model to 1e-20); say so where it fails rather than project
    residual = np.abs(V @ A - Phi @ V).max() / np.abs(Phi @ V).max()
    if residual > 1e-8:
        raise RuntimeError(
            f"the flexible modes' subspace is not invariant under the mesh period's map "
            f"(residual {residual:.1e}): the rigid-body motion is driven by the meshes"
        )
    return A


def _waves(meshes: Meshes):
    """``v(s)``: every mesh's relative stiffness variation at the mesh angle ``s``."""

    def v(s: float) -> np.ndarray:
        out = np.zeros(len(meshes.rows))
        for j, (gamma, wave) in enumerate(zip(meshes.phases, meshes.waveform, strict=True)):
            for h, (a, b) in enumerate(wave, start=1):
                phase = h * (s - 2.0 * math.pi * gamma)
                out[j] += a * math.cos(phase) + b * math.sin(phase)
        return out

    return v


def _integrated(rhs, size: int, rtol: float) -> np.ndarray:
    """The fundamental matrix of ``rhs`` over one mesh angle ``0 .. 2 pi`` by DOP853."""
    sol = scipy.integrate.solve_ivp(
        rhs,
        (0.0, 2.0 * math.pi),
        np.eye(size).ravel(),
        method="DOP853",
        rtol=rtol,
        atol=rtol * 1e-2,
    )
    if not sol.success:
        raise RuntimeError(f"the monodromy matrix could not be integrated: {sol.message}")
    return sol.y[:, -1].reshape(size, size)


def holding(found: list[Instability], Omega: float) -> list[Instability]:
    """The bands of ``found`` the phasing keeps (first order) that hold the mesh frequency
    ``Omega``: where a suppressed band's centre is unstable by the multipliers, whether it
    lies in another band (at speed a split pair's bands overlap) or is a band of higher
    order."""
    return [i for i in found if not i.suppressed and i.lower <= Omega <= i.upper]


def unstable(mu: np.ndarray, threshold: float = 1e-7) -> bool:
    """Whether a multiplier lies outside the unit circle by more than ``threshold`` (the
    undamped set's multipliers sit on it, to the integration's error, where stable)."""
    return bool(np.abs(mu).max() > 1.0 + threshold)


def floquet_band(
    structure: dict, meshes: Meshes, ins: Instability, *, span: float = 3.0, tol: float = 1e-9
) -> tuple[float, float]:
    """The edges of the instability band ``ins`` by the Floquet multipliers: bisection from
    its centre (which must be unstable) to the first stable point found stepping outwards
    by quarter first-order half-widths (at most ``span`` of them), to ``tol`` relative.
    Raises ``ValueError`` where either end fails."""
    centre, half = ins.centre, 0.5 * (ins.upper - ins.lower)
    if half <= 0.0 or not unstable(multipliers(structure, meshes, centre)):
        raise ValueError(f"harmonic {ins.l}, modes {ins.modes}: stable at the band's centre")
    edges = []
    for sign in (-1.0, 1.0):
        # out from the centre in quarter half-widths to the first stable point (a
        # neighbouring band, a combination resonance, may begin past a stable gap)
        inside = centre
        for step in np.arange(1.25, span + 1e-9, 0.25):
            outside = centre + sign * step * half
            if not unstable(multipliers(structure, meshes, outside)):
                break
            inside = outside
        else:
            raise ValueError(
                f"harmonic {ins.l}, modes {ins.modes}: still unstable {span} half-widths out"
            )
        while abs(outside - inside) > tol * centre:
            mid = 0.5 * (inside + outside)
            if unstable(multipliers(structure, meshes, mid)):
                inside = mid
            else:
                outside = mid
        edges.append(0.5 * (inside + outside))
    return edges[0], edges[1]
