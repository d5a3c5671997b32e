"""Newton's law in body coordinates with every mesh a dead zone (issue 26): what a planetary
set's nonlinear model (``planetary_dynamics.py``) and a closed-loop train's
(``train_dynamics.py``) share.

The linear model of the bodies (``M`` diagonal over the body coordinates ``q``, each
spring a row ``r_j`` of ``R`` with its mean stiffness ``k_j``) with each mesh's force
``k_j (1 + v_j(t)) b_j g(delta_j / b_j)`` along its line of action, ``g`` the exact dead zone
(``g(u) = u - 1`` beyond the gap, ``u + 1`` before it, zero inside: the teeth apart), ``b_j``
its half backlash and ``v_j`` its stiffness variation; every other spring linear; every
spring a damper ``c_j delta_j'`` with ``c_j = 2 zeta sqrt(k_j m_j)``, ``1 / m_j = r_j M^-1
r_j^T`` (the mass its deflection sees), the mesh's whether or not its teeth touch (as in the
tree models, after Kahraman and Singh, 1990).  With a load ``F`` per unit ``f``:

    ``M q'' = f F - sum_j r_j^T (k_j (1 + v_j) b_j g(r_j q / b_j) + c_j r_j q')``.

**The rigid-body rotation** (``R phi_0 = 0``, at most one) is removed, not integrated: its
coordinate would drift with any round-off in its speed and give every periodic orbit a
multiplier 1.  ``q`` is measured from the rigid rotation that carries the bodies' momentum,
``phi_0^T M q = 0``, which fixes the coordinate with the largest ``|M_ii phi_0,i|`` (the
pivot) by the others: ``q = T y``.  Because ``phi_0^T M T = 0``, ``R phi_0 = 0`` and ``phi_0^T F
= 0`` (the caller's load leaves that rotation unforced), the rigid coordinate stays at rest
and ``T^T M T y'' = T^T (f F - R^T f_springs)`` is exact.

**Scales.**  Lengths in the reference mesh's half backlash ``b``, time ``tau = omega_n t``
with ``omega_n = sqrt(k_ref / m_ref)`` of that mesh: ``y = b ybar``, ``A = T^T M T / m_ref``,

    ``ybar'' = A^-1 [f e - sum_j t_j (kappa_j (1 + v_j) beta_j g(u_j) + 2 zeta mu_j u_j')]``

with ``t_j = T^T r_j^T``, ``kappa_j = k_j / k_ref``, ``beta_j = b_j / b``, ``mu_j = sqrt(kappa_j
m_j / m_ref)``, ``u_j = r_j T ybar / beta_j`` and ``e = A^-1 T^T F / (k_ref b)`` per unit ``f``
(the caller gives ``F / (k_ref b)``).
The variation ``v_j = sum_l c_l cos(h_l omega tau) + s_l sin(h_l omega tau)``, each term at
its own multiple ``h_l`` of the forcing frequency ``omega``.

**A rotating frame** (``Bodies.frame``: a planetary set's carrier turning at ``Omega``,
``planetary.py``) adds ``- Omega G q' + Omega^2 K_Omega q`` to the forces, both linear.  The
rigid-body rotation ``phi_0`` is then the null vector of ``K - Omega^2 K_Omega``
(:func:`frame_rotation`), not of ``R``: its meshes' rows of ``R phi_0`` are zero, its
planets' bearings' tangential rows are not (``d / r_c``, the spring turning with the set at
its static stretch ``d``).  The dampers act on ``R T y'`` only: they are taken not to see
that turning, which is no stretch.  ``G phi_0`` is not zero (a planet moving radially
changes the set's moment of inertia), so the rigid coordinate ``s = phi_0^T M q`` is no
longer at rest: ``p = s' + Omega phi_0^T G q`` is conserved (``phi_0^T`` times the
equations: the stiffness terms vanish with ``(K - Omega^2 K_Omega) phi_0 = 0``, the meshes'
with their rows, the load by the carrier's reaction, the dampers as just said), and with
``p = 0`` (the frame turns with the set's momentum) ``s' = - Omega phi_0^T G T y`` follows
from ``y`` alone, ``s`` itself entering nowhere.  With
``q = T y + phi_0 s / m_0`` (``m_0 = phi_0^T M phi_0``) the frame's force on ``y`` is

    ``- Omega T^T G T y' + Omega^2 (T^T K_Omega T - g g^T / m_0) y``,  ``g = T^T G phi_0``,

the last term the momentum's stiffening (``phi_0^T G T = -g^T``, ``G`` skew).  Scaled:
``W = Omega / omega_n`` and both matrices over ``m_ref``.  ``y`` is measured from the
static stretch of the planets' bearings under their centripetal load, which the meshes
do not share (the loader refuses a set where they would).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import sympy as sp

__all__ = [
    "BodyDynamics",
    "Bodies",
    "build",
    "frame_rotation",
    "frame_stiffness",
    "reduction",
    "structure_mapping",
]


@dataclass(frozen=True)
class Bodies:
    """What :func:`build` needs of a model in body coordinates."""

    physical: tuple[str, ...]  # q
    mass: tuple[float, ...]  # M's diagonal
    springs: tuple[str, ...]  # the name of each row of R
    kinds: tuple[str, ...]  # "mesh" or any other (linear)
    incidence: np.ndarray  # R (springs x q)
    stiffness: tuple[float, ...]  # k_j
    rigid_body_modes: int  # 0 or 1 (the caller refuses more)
    half_backlash_m: dict  # mesh row index -> b_j
    waves: dict  # mesh row index -> ((h, c, s), ...)
    labels: dict  # mesh row index -> its kind's name in MESHES ("sun-planet", "mesh", ...)
    load: np.ndarray  # F / (k_ref b) per unit f on each q (phi_0^T F = 0)
    reference: int  # the mesh row whose k, m and b set the scales
    # mesh row index -> ((h, c, s), ...): its transmission error in m, sum_l c_l cos(h_l
    # omega tau) + s_l sin(h_l omega tau), added to its deflection (excess material)
    errors: dict = field(default_factory=dict)
    # the carrier's rotating frame: (Omega rad/s, G, K_Omega) over q, or None (no frame)
    frame: tuple | None = None


@dataclass(frozen=True)
class BodyDynamics:
    """A nonlinear model in body coordinates in the emitters' terms (``states``,
    ``state_symbols``, ``parameter_symbols``, ``rhs``, ``jacobian`` flat, ``parameters``),
    with what the generated module states about it."""

    structure: object  # the linear model it was built from (planetary or train)
    name: str
    description: str
    source: str  # the file it was derived from
    title: str  # "planetary set", "gear train"
    coordinates: tuple[str, ...]  # y: every body coordinate but the pivot
    pivot: str | None  # the coordinate fixed by the others (None: no rigid-body mode)
    states: tuple[str, ...]
    state_symbols: tuple[sp.Symbol, ...]
    parameter_symbols: tuple[sp.Symbol, ...]
    parameters: tuple[tuple[str, float], ...]  # (name, default)
    rhs: tuple[sp.Expr, ...]
    jacobian: tuple[sp.Expr, ...]  # row-major, n x n
    meshes: dict  # mesh -> {"row": coefficients of u_j over y, "half_backlash_m", ...}
    transform: np.ndarray  # T (q x y): q = b T ybar
    length_m: float  # b
    omega_n: float  # rad/s
    stiffness: np.ndarray  # K_bar (y x y): the mean stiffness, every mesh's teeth touching
    load_direction: np.ndarray  # T^T F / (k_ref b) per unit f (static: K_bar ybar = f this + gaps)
    k_ref: float  # N/m: the reference mesh's mean stiffness
    # (user name, parameter, factor to it, rule "positive" | "unit" | "nonnegative", words)
    physical: tuple = ()
    data: dict = field(default_factory=dict)  # more data the module states (name -> value)


def structure_mapping(st, motions) -> dict:
    """The ``STRUCTURE`` mapping of a generated module (``solver.analysis.modes``) of a
    linear model in body coordinates (a planetary set's or a train's: ``physical``,
    ``mass``, ``springs``, ``kinds``, ``incidence``, ``stiffness``, ``members``), each
    coordinate's ``motions``."""
    return {
        "physical": st.physical,
        "mass": st.mass,
        "coordinates": st.springs,
        "kinds": st.kinds,
        "incidence": tuple(tuple(float(v) for v in row) for row in st.incidence),
        "stiffness": st.stiffness,
        "members": st.members,
        "motions": tuple(motions),
    }


def reduction(physical, mass, R, rigid: int, phi=None):
    """(T, pivot name or None, phi_0): the reduction of the one rigid-body rotation
    (module docstring); ``rigid`` 0: none, T the identity.  ``phi``: the rotation where it
    is not ``R``'s null vector (a rotating frame's, :func:`frame_rotation`)."""
    n = len(physical)
    if rigid == 0:
        return np.eye(n), None, None
    if phi is None:
        phi = np.linalg.svd(R)[2][-1]
    m = np.asarray(mass)
    p = int(np.argmax(np.abs(m * phi)))
    keep = [i for i in range(n) if i != p]
    T = np.zeros((n, n - 1))
    for col, i in enumerate(keep):
        T[i, col] = 1.0
        T[p, col] = -m[i] * phi[i] / (m[p] * phi[p])
    return T, physical[p], phi


def frame_stiffness(R, k, frame) -> np.ndarray:
    """``K - Omega^2 K_Omega`` over ``q``: the springs' stiffness and the rotating frame's
    centripetal terms (``frame``: ``(Omega, G, K_Omega)``)."""
    speed, _, K_omega = frame
    return R.T @ (np.asarray(k)[:, None] * R) - speed**2 * np.asarray(K_omega, dtype=float)


def frame_rotation(mass, R, k, frame) -> np.ndarray:
    """The rigid-body rotation of a set in a rotating frame (``frame``: ``(Omega, G,
    K_Omega)``): the null vector of ``K - Omega^2 K_Omega``, not of ``R``.  Turning with the
    set, each planet sits at its bearing's static stretch ``d`` beyond ``r_c``, so it moves
    by ``(1 + d / r_c)`` times the carrier's ``u_c``: the bearing's tangential "deflection"
    in this mode is the spring turning with the set, which ``K_Omega``'s load term on
    ``u_c`` balances (``planetary.py``), and the meshes' deflections stay zero."""
    K = frame_stiffness(R, k, frame)
    m = np.asarray(mass, dtype=float)
    w2, V = np.linalg.eigh(K / np.sqrt(np.outer(m, m)))
    return V[:, np.argmin(np.abs(w2))] / np.sqrt(m)


def reference_scales(b: Bodies) -> tuple[float, float]:
    """(k_ref, omega_n) of the reference mesh."""
    R, k = b.incidence, np.asarray(b.stiffness)
    m_ref = 1.0 / float(np.sum(R[b.reference] ** 2 / np.asarray(b.mass)))
    return float(k[b.reference]), float(np.sqrt(k[b.reference] / m_ref))


def _frame(b: Bodies, T, phi, M, m_ref: float, omega_n: float):
    """``(W G_r, W^2 K_r)`` over ``y``, scaled by ``m_ref``: the rotating frame's forces
    ``- W G_r ybar' + W^2 K_r ybar`` (module docstring); zeros without a frame."""
    n_y = T.shape[1]
    if b.frame is None:
        return np.zeros((n_y, n_y)), np.zeros((n_y, n_y))
    speed, G, K_omega = b.frame
    G, K_omega = np.asarray(G, dtype=float), np.asarray(K_omega, dtype=float)
    W = speed / omega_n
    gyro = W * (T.T @ G @ T) / m_ref
    centri = T.T @ K_omega @ T
    if phi is not None:
        g = T.T @ G @ phi
        centri = centri - np.outer(g, g) / float(phi @ M @ phi)
    centri = W**2 * centri / m_ref
    return _rounding_dropped(gyro), _rounding_dropped(centri)


def _rounding_dropped(a: np.ndarray) -> np.ndarray:
    """``a`` with entries below 1e-15 of its largest set to zero: rounding of ``T``'s pivot
    row and of ``A^-1``, which would otherwise put every coordinate in every equation."""
    a = np.array(a, dtype=float)
    a[np.abs(a) < 1e-15 * max(np.max(np.abs(a), initial=0.0), 1e-300)] = 0.0
    return a


def build(b: Bodies, symbols=("omega", "f", "zeta")) -> dict:
    """The fields of :class:`BodyDynamics` that the equations give (``coordinates``,
    ``pivot``, ``states``, the symbols, ``rhs``, ``jacobian``, ``meshes``, ``transform``,
    ``length_m``, ``omega_n``, ``stiffness``, ``load_direction``, ``k_ref``); ``symbols``:
    the names of the forcing frequency, the load and the damping ratio."""
    R, k, kinds = b.incidence, np.asarray(b.stiffness), b.kinds
    M = np.diag(b.mass)
    turning = b.frame if b.rigid_body_modes else None
    phi = None if turning is None else frame_rotation(b.mass, R, k, turning)
    T, pivot, phi = reduction(b.physical, b.mass, R, b.rigid_body_modes, phi)
    if turning is not None:
        moved = np.abs(R @ phi)[[j for j, kind in enumerate(kinds) if kind == "mesh"]]
        if np.max(moved) > 1e-9 * np.max(np.abs(R @ phi), initial=1e-300) + 1e-12:
            raise ValueError("the rigid-body rotation at this carrier speed moves a mesh")
    n_y = T.shape[1]
    m_j = 1.0 / np.einsum("ji,i,ji->j", R, 1.0 / np.asarray(b.mass), R)
    ref = b.reference
    k_ref, m_ref, length = k[ref], m_j[ref], b.half_backlash_m[ref]
    omega_n = float(np.sqrt(k_ref / m_ref))
    A = T.T @ M @ T / m_ref
    Ainv = np.linalg.inv(A)
    load = T.T @ b.load
    e = Ainv @ load  # per unit f
    rows = R @ T  # delta_j = b rows_j ybar
    beta = np.array(
        [b.half_backlash_m[j] / length if kinds[j] == "mesh" else 1.0 for j in range(len(k))]
    )
    kappa = k / k_ref
    mu = np.sqrt(kappa * m_j / m_ref)  # c_j omega_n / k_ref over 2 zeta

    gyro_r, centri_r = _frame(b, T, phi, M, m_ref, omega_n)
    gyro, centri = _rounding_dropped(Ainv @ gyro_r), _rounding_dropped(Ainv @ centri_r)
    tau = sp.Symbol("tau")
    omega, f, zeta = sp.symbols(" ".join(symbols))
    coords = tuple(c for c in b.physical if c != pivot)
    y = tuple(sp.Symbol(c, real=True) for c in coords)
    dy = tuple(sp.Symbol(f"d{c}", real=True) for c in coords)
    forces = []
    for j in range(len(k)):
        delta = sum(float(rows[j, i]) * y[i] for i in range(n_y) if rows[j, i] != 0.0)
        rate = sum(float(rows[j, i]) * dy[i] for i in range(n_y) if rows[j, i] != 0.0)
        if kinds[j] == "mesh" and b.errors.get(j):
            error = sum(  # in the reference half backlash, as delta
                c_l / length * sp.cos(h * omega * tau) + s_l / length * sp.sin(h * omega * tau)
                for h, c_l, s_l in b.errors[j]
            )
            delta, rate = delta + error, rate + sp.diff(error, tau)
        if kinds[j] == "mesh":
            u = delta / float(beta[j])
            g = sp.Piecewise((u - 1, u > 1), (u + 1, u < -1), (0, True))
            var = 1 + sum(
                c_l * sp.cos(h * omega * tau) + s_l * sp.sin(h * omega * tau)
                for h, c_l, s_l in b.waves.get(j, ())
            )
            elastic = float(kappa[j] * beta[j]) * var * g
        else:
            elastic = float(kappa[j]) * delta
        forces.append(elastic + 2 * zeta * float(mu[j]) * rate)
    G = Ainv @ rows.T  # column j: A^-1 t_j
    acc = []
    for i in range(n_y):
        terms = [float(G[i, j]) * forces[j] for j in range(len(k)) if abs(G[i, j]) > 1e-15]
        # the rotating frame's forces through A^-1 (none without a frame)
        frame = [
            -float(gyro[i, c]) * dy[c] + float(centri[i, c]) * y[c]
            for c in range(n_y)
            if gyro[i, c] != 0.0 or centri[i, c] != 0.0
        ]
        acc.append(f * float(e[i]) - sp.Add(*terms) + sp.Add(*frame))
    rhs = tuple(dy) + tuple(acc)
    states = tuple(y) + dy
    jac = tuple(sp.diff(r, s) for r in rhs for s in states)
    meshes = {
        b.springs[j]: {
            "row": tuple(float(v / beta[j]) for v in rows[j]),
            "half_backlash_m": float(beta[j] * length),
            # kappa beta^2: its spring is weight row^T row, its closed gap weight row
            "weight": float(kappa[j] * beta[j] ** 2),
            # v(tau) = sum_l c_l cos(h_l omega tau) + s_l sin(h_l omega tau): its variation
            "wave": tuple(b.waves.get(j, ())),
            # e(tau) in its own half backlashes, added to its deflection (none: ())
            "error": tuple(
                (h, c_l / (beta[j] * length), s_l / (beta[j] * length))
                for h, c_l, s_l in b.errors.get(j, ())
            ),
            "kind": b.labels[j],
        }
        for j in range(len(k))
        if kinds[j] == "mesh"
    }
    return {
        "coordinates": coords,
        "pivot": pivot,
        "states": coords + tuple(f"d{c}" for c in coords),
        "state_symbols": states,
        "parameter_symbols": (omega, f, zeta),
        "rhs": rhs,
        "jacobian": jac,
        "meshes": meshes,
        "transform": T,
        "length_m": float(length),
        "omega_n": omega_n,
        # every mesh's teeth touching, and the frame's centripetal and momentum terms
        "stiffness": rows.T @ np.diag(kappa) @ rows - centri_r,
        "load_direction": load,
        "k_ref": float(k_ref),
    }
