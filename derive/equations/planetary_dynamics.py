"""The nonlinear model of a planetary set: backlash in every mesh (issue 26, point 5).

The linear model (``planetary.py``: ``M``, the springs' rows ``r_j`` of ``R`` and mean
stiffnesses ``k_j``) with each mesh's force ``k_j (1 + v_j(t)) b_j g(delta_j / b_j)`` along its
line of action, ``g`` the exact dead zone (``g(u) = u - 1`` beyond the gap, ``u + 1`` before
it, zero inside: the teeth apart), ``b_j`` the mesh's half backlash and ``v_j`` its stiffness
variation (``[planetary.variation]``: the rectangular wave delayed by the mesh's phase;
none without that table); every bearing and support a linear spring; every spring a
damper ``c_j delta_j'`` with ``c_j = 2 zeta sqrt(k_j m_j)``, ``1 / m_j = r_j M^-1 r_j^T`` (the
mass its deflection sees), the mesh's whether or not its teeth touch (as in the tree
models, after Kahraman and Singh, 1990).  Newton's law in the body coordinates ``q``:

    ``M q'' = F - sum_j r_j^T (k_j (1 + v_j) b_j g(r_j q / b_j) + c_j r_j q')``.

**The load.**  The sun's torque, as the force ``F_s`` it puts on the sun's base circle
(``u_s = r_s theta_s``), drives; where the set turns as a rigid body (``R phi_0 = 0``), the
carrier takes the reaction that leaves that rotation unforced, ``phi_0^T F = 0``: the
steady operation of a set whose output is the carrier.  A set that no member's support
leaves free to turn carries the load in its supports.

**The rigid-body rotation** is removed, not integrated: its coordinate would drift with
any round-off in its speed and give every periodic orbit a multiplier 1.  ``q`` is measured
from the rigid rotation that carries the set's momentum, ``phi_0^T M q = 0``, which fixes
the coordinate with the largest ``|M_ii phi_0,i|`` (the pivot) by the others: ``q = T y``,
``y`` every other coordinate.  Because ``phi_0^T M T = 0``, ``R phi_0 = 0`` and ``phi_0^T F = 0``,
the rigid coordinate stays at rest and ``T^T M T y'' = T^T (F - R^T f)`` is exact.  More than
one rigid-body mode (two members free with nothing holding the set) is refused.

**Scales.**  Lengths in the sun-planet half backlash ``b``, time ``tau = omega_n t`` with
``omega_n = sqrt(k_sp / m_sp)`` of the first sun-planet mesh: ``y = b ybar``, and

    ``ybar'' = A^-1 [f e - sum_j t_j (kappa_j (1 + v_j) beta_j g(u_j) + 2 zeta mu_j u_j'...)]``,

written out in :func:`derive_dynamics`.  Forcing frequency ``omega``: the mesh frequency
over ``omega_n``; ``f = F_s / (k_sp b)``.  The stiffness variation enters as
``v_j = sum_l a_l cos(l (omega tau - 2 pi gamma_j)) + b_l sin(l (omega tau - 2 pi gamma_j))``.
No transmission error.  The carrier's rotating frame is not modelled here (a turning
carrier's set is refused).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import sympy as sp

from ..input.reader import InputError
from .planetary import PlanetaryStructure, planetary_meshes

__all__ = ["PlanetaryDynamics", "derive_dynamics", "needs_dynamics", "scales"]


@dataclass(frozen=True)
class PlanetaryDynamics:
    """The nonlinear model of a planetary set in the emitters' terms (``states``,
    ``state_symbols``, ``parameter_symbols``, ``rhs``, ``jacobian`` flat, ``parameters``),
    with what the generated module states about it."""

    structure: PlanetaryStructure
    name: str
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
    load_direction: np.ndarray  # T^T F per unit f (static: K_bar ybar = f this + gaps)
    k_ref: float  # N/m: the reference (first sun-planet) mesh's mean stiffness


def _pivot(st: PlanetaryStructure):
    """(T, pivot name or None, phi_0): the reduction of the rigid-body rotation."""
    n = len(st.physical)
    R = st.incidence
    if st.rigid_body_modes == 0:
        return np.eye(n), None, None
    if st.rigid_body_modes > 1:
        raise InputError(
            st.planetary.source,
            "planetary",
            f"{st.rigid_body_modes} rigid-body modes: the nonlinear model removes one (the "
            "set turning as a whole); hold another member (its torsional_N_per_m)",
        )
    _, _, vt = np.linalg.svd(R)
    phi = vt[-1]
    m = np.asarray(st.mass)
    p = int(np.argmax(np.abs(m * phi)))
    keep = [i for i in range(n) if i != p]
    T = np.zeros((n, n - 1))
    for col, i in enumerate(keep):
        T[i, col] = 1.0
        T[p, col] = -m[i] * phi[i] / (m[p] * phi[p])
    return T, st.physical[p], phi


def _variation(st: PlanetaryStructure) -> dict:
    """mesh row index -> ((c_l, s_l), ...): v_j's coefficients of cos and sin of l omega tau."""
    if st.planetary.variation is None or st.phases is None:
        return {}
    rows, phases, waves = planetary_meshes(st)
    out = {}
    for j, gamma, wave in zip(rows, phases, waves, strict=True):
        terms = []
        for h, (a, b) in enumerate(wave, start=1):
            phi = 2 * math.pi * h * gamma
            c, s = math.cos(phi), math.sin(phi)
            terms.append((a * c - b * s, a * s + b * c))
        out[j] = tuple(terms)
    return out


def needs_dynamics(ps) -> None:
    """``InputError`` (one line) where the set's file cannot give the nonlinear model:
    no ``[planetary.dynamics]`` table, or a turning carrier."""
    if ps.dynamics is None:
        raise InputError(
            ps.source,
            "planetary.dynamics",
            "simulate, sweep, map, shoot, continue and frequency-response need the nonlinear "
            "model, and it needs a [planetary.dynamics] table (sun_force_N, the half "
            "backlashes, mesh_frequency_hz); add one (docs/user-guide.md, Planetary sets), or "
            "run `gearsym modes` on the set",
        )
    if ps.carrier_speed_rpm:
        raise InputError(
            ps.source,
            "planetary.carrier_speed_rpm",
            "the nonlinear model is of the carrier's frame without its gyroscopic and "
            "centripetal terms; leave the carrier speed out for it",
        )


def _load(st: PlanetaryStructure, phi) -> np.ndarray:
    """F per unit sun force: 1 on ``u_s``, and the carrier's reaction where the set can
    turn as a whole (``phi``: its rigid-body rotation, or None)."""
    F = np.zeros(len(st.physical))
    F[st.physical.index("u_s")] = 1.0
    if phi is not None:
        c = st.physical.index("u_c")
        if abs(phi[c]) < 1e-12 * np.max(np.abs(phi)):
            raise InputError(
                st.planetary.source,
                "planetary.carrier",
                "the carrier does not turn with the set's rigid-body rotation, so it "
                "cannot take the sun's reaction; free the carrier and hold the ring",
            )
        F[c] = -phi[st.physical.index("u_s")] / phi[c]
    return F


def scales(st: PlanetaryStructure) -> dict:
    """The nonlinear model's numbers that need no SymPy (for the audit page): the pivot,
    the length and time scales, and the defaults of its parameters."""
    ps = st.planetary
    needs_dynamics(ps)
    d = ps.dynamics
    _, pivot, phi = _pivot(st)
    _load(st, phi)  # refused where the carrier cannot take the reaction
    R, k, names = st.incidence, np.asarray(st.stiffness), st.springs
    ref = next(j for j, kind in enumerate(st.kinds) if kind == "mesh" and names[j][0] == "s")
    m_ref = 1.0 / float(np.sum(R[ref] ** 2 / np.asarray(st.mass)))
    omega_n = math.sqrt(k[ref] / m_ref)
    return {
        "pivot": pivot,
        "length_m": d.backlash_sun,
        "omega_n": omega_n,
        "omega": 2 * math.pi * d.mesh_frequency_hz / omega_n,
        "f_s": d.sun_force / (k[ref] * d.backlash_sun),
        "reference": names[ref],
    }


def derive_dynamics(st: PlanetaryStructure) -> PlanetaryDynamics:
    """The nonlinear model of ``st`` (module docstring); ``InputError`` where it cannot
    be built (no ``[planetary.dynamics]``, a turning carrier, two rigid-body modes)."""
    ps = st.planetary
    needs_dynamics(ps)
    d = ps.dynamics
    R, k, kinds, names = st.incidence, np.asarray(st.stiffness), st.kinds, st.springs
    M = np.diag(st.mass)
    Minv = np.diag(1.0 / np.asarray(st.mass))
    T, pivot, phi = _pivot(st)
    n_y = T.shape[1]
    meshes = [j for j, kind in enumerate(kinds) if kind == "mesh"]
    sun_meshes = [j for j in meshes if names[j].startswith("s")]
    ref = sun_meshes[0]
    m_j = 1.0 / np.einsum("ji,i,ji->j", R, np.diag(Minv), R)
    k_ref, m_ref, b = k[ref], m_j[ref], d.backlash_sun
    scale = scales(st)
    omega_n = scale["omega_n"]
    # the load: F_s on u_s, the carrier's reaction where the set can turn as a whole
    F = _load(st, phi)
    A = T.T @ M @ T / m_ref
    Ainv = np.linalg.inv(A)
    e = Ainv @ (T.T @ F)  # per unit f
    rows = R @ T  # delta_j = b rows_j ybar
    beta = np.array(
        [
            (d.backlash_sun if names[j].startswith("s") else d.backlash_ring) / b
            if kinds[j] == "mesh"
            else 1.0
            for j in range(len(k))
        ]
    )
    kappa = k / k_ref
    mu = np.sqrt(kappa * m_j / m_ref)  # c_j omega_n / k_ref over 2 zeta
    wave = _variation(st)

    tau = sp.Symbol("tau")
    omega, f, zeta = sp.symbols("omega f_s zeta")
    coords = tuple(c for c in st.physical if c != pivot)
    y = tuple(sp.Symbol(c, real=True) for c in coords)
    dy = tuple(sp.Symbol(f"d{c}", real=True) for c in coords)
    forces = []
    for j in range(len(k)):
        delta = sum(float(rows[j, i]) * y[i] for i in range(n_y) if rows[j, i] != 0.0)
        rate = sum(float(rows[j, i]) * dy[i] for i in range(n_y) if rows[j, i] != 0.0)
        if kinds[j] == "mesh":
            u = delta / float(beta[j])
            g = sp.Piecewise((u - 1, u > 1), (u + 1, u < -1), (0, True))
            var = 1 + sum(
                c_l * sp.cos(h * omega * tau) + s_l * sp.sin(h * omega * tau)
                for h, (c_l, s_l) in enumerate(wave.get(j, ()), start=1)
            )
            elastic = float(kappa[j] * beta[j]) * var * g
        else:
            elastic = float(kappa[j]) * delta
        forces.append(elastic + 2 * zeta * float(mu[j]) * rate)
    G = Ainv @ rows.T  # column j: A^-1 t_j
    acc = []
    for i in range(n_y):
        terms = [float(G[i, j]) * forces[j] for j in range(len(k)) if abs(G[i, j]) > 1e-15]
        acc.append(f * float(e[i]) - sp.Add(*terms))
    rhs = tuple(dy) + tuple(acc)
    states = tuple(y) + dy
    jac = tuple(sp.diff(r, s) for r in rhs for s in states)
    K_bar = rows.T @ np.diag(kappa) @ rows  # every mesh's teeth touching
    mesh_info = {
        names[j]: {
            "row": tuple(float(v / beta[j]) for v in rows[j]),
            "half_backlash_m": float(beta[j] * b),
            # kappa beta^2: its spring is weight row^T row, its closed gap weight row
            "weight": float(kappa[j] * beta[j] ** 2),
            # v(tau) = sum_l c_l cos(l omega tau) + s_l sin(l omega tau): its variation
            "wave": tuple(wave.get(j, ())),
            "kind": "sun-planet" if names[j].startswith("s") else "ring-planet",
        }
        for j in meshes
    }
    defaults = (("omega", scale["omega"]), ("f_s", scale["f_s"]), ("zeta", d.damping_ratio))
    return PlanetaryDynamics(
        structure=st,
        name=ps.name,
        coordinates=coords,
        pivot=pivot,
        states=coords + tuple(f"d{c}" for c in coords),
        state_symbols=states,
        parameter_symbols=(omega, f, zeta),
        parameters=defaults,
        rhs=rhs,
        jacobian=jac,
        meshes=mesh_info,
        transform=T,
        length_m=b,
        omega_n=omega_n,
        stiffness=K_bar,
        load_direction=T.T @ F,
        k_ref=float(k_ref),
    )
