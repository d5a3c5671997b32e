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

**The rigid-body rotation** is removed and the equations scaled as ``body_dynamics.py``
states (one pivot coordinate follows from the others; more than one rigid-body mode, two
members free with nothing holding the set, is refused): lengths in the sun-planet half
backlash ``b``, time ``tau = omega_n t`` with ``omega_n = sqrt(k_sp / m_sp)`` of the first
sun-planet mesh, forcing frequency ``omega``: the mesh frequency
over ``omega_n``; ``f = F_s / (k_sp b)``.  The stiffness variation enters as
``v_j = sum_l a_l cos(l (omega tau - 2 pi gamma_j)) + b_l sin(l (omega tau - 2 pi gamma_j))``.
A transmission error (``sun_planet_transmission_error``, ``ring_planet_transmission_error``)
is excess material on the loaded flank (the sun's force makes every mesh's ``delta > 0``),
delayed by each mesh's phase as its stiffness variation is (``_errors``).

**A turning carrier** (``carrier_speed_rpm``): the linear model's gyroscopic and centripetal
terms at the file's speed (``planetary.py``), with the rigid-body rotation's momentum, as
``body_dynamics.py`` states.  The speed is the file's, fixed: the forcing frequency moves
without it (a frequency response holds the frame's terms, as Lin and Parker's equations
hold ``Omega_c`` apart from the mesh frequency); another speed is another file.  The
module states the speed and the mesh frequency it gives (``FRAME``), so that a command run
at another mesh frequency says so.
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from ..input.planetary import needs_dynamics  # re-exported: the derivation's check
from ..input.reader import InputError
from .body_dynamics import (
    Bodies,
    BodyDynamics,
    build,
    frame_rotation,
    frame_stiffness,
    reduction,
)
from .planetary import PlanetaryStructure, planetary_meshes

__all__ = [
    "PlanetaryDynamics",
    "derive_dynamics",
    "mesh_frequency_of_speed",
    "needs_dynamics",
    "scales",
]


# the model's record: the same for every model in body coordinates
PlanetaryDynamics = BodyDynamics


def _pivot(st: PlanetaryStructure):
    """(T, pivot name or None, phi_0): the reduction of the rigid-body rotation."""
    if st.rigid_body_modes > 1:
        raise InputError(
            st.planetary.source,
            "planetary",
            f"{st.rigid_body_modes} rigid-body modes: the nonlinear model removes one (the "
            "set turning as a whole); hold another member (its torsional_N_per_m)",
        )
    phi = None
    if st.carrier_speed_rad_s and st.rigid_body_modes:
        phi = frame_rotation(st.mass, st.incidence, st.stiffness, _frame(st))
    return reduction(st.physical, st.mass, st.incidence, st.rigid_body_modes, phi)


def _variation(st: PlanetaryStructure) -> dict:
    """mesh row index -> ((l, c_l, s_l), ...): v_j's coefficients of cos and sin of l omega
    tau."""
    if st.planetary.variation is None or st.phases is None:
        return {}
    rows, phases, waves = planetary_meshes(st)
    out = {}
    for j, gamma, wave in zip(rows, phases, waves, strict=True):
        terms = []
        for h, (a, b) in enumerate(wave, start=1):
            phi = 2 * math.pi * h * gamma
            c, s = math.cos(phi), math.sin(phi)
            terms.append((h, a * c - b * s, a * s + b * c))
        out[j] = tuple(terms)
    return out


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


def _frame(st: PlanetaryStructure):
    """``(Omega, G, K_Omega)`` of a turning carrier, or None."""
    if not st.carrier_speed_rad_s:
        return None
    return st.carrier_speed_rad_s, st.gyroscopic, st.centripetal


def _definite(st: PlanetaryStructure) -> None:
    """``InputError`` where the carrier's speed makes the stiffness ``K - Omega^2 K_Omega``
    indefinite (as ``gearsym modes`` refuses it): the set diverges there, or is held at
    best by its gyroscopic terms, which damping turning with the carrier undoes."""
    m = np.asarray(st.mass)
    K = frame_stiffness(st.incidence, st.stiffness, _frame(st))
    w2 = np.linalg.eigvalsh(K / np.sqrt(np.outer(m, m)))
    count = int(np.sum(w2 < -1e-10 * np.max(np.abs(w2))))
    if count:
        raise InputError(
            st.planetary.source,
            "planetary.carrier_speed_rpm",
            f"at {st.planetary.carrier_speed_rpm:g} rpm the centripetal terms make the "
            f"stiffness indefinite ({count} negative direction{'s' if count > 1 else ''}): "
            "the set diverges, or is held at best by its gyroscopic terms, which the "
            "dampers undo; lower the speed",
        )


def _errors(st: PlanetaryStructure) -> dict:
    """mesh row index -> ((l, c_l, s_l), ...): each mesh's transmission error in m (its
    kind's harmonics, delayed by the mesh's phase as its stiffness is); excess material on
    the loaded flank, which the sun's force makes ``delta > 0`` for every mesh."""
    d = st.planetary.dynamics
    if d.error_sun is None and d.error_ring is None:
        return {}
    if st.phases is None:
        raise InputError(
            st.planetary.source,
            "planetary.dynamics",
            "a transmission error is delayed by each mesh's phase, which needs sun_teeth "
            "and ring_teeth in [planetary]; give them",
        )
    v = st.planetary.variation
    offset = v.ring_sun_phase if v is not None else 0.0
    out = {}
    for j, (name, kind) in enumerate(zip(st.springs, st.kinds, strict=True)):
        te = d.error_sun if name.startswith("s") else d.error_ring
        if kind != "mesh" or te is None:
            continue
        sun, ring = st.phases[int(name[2:]) - 1]
        gamma = sun if name.startswith("s") else (ring + offset) % 1.0
        terms = []
        for h, (a, phi) in enumerate(zip(te.amplitudes, te.phases, strict=True), start=1):
            psi = 2 * math.pi * h * gamma - phi  # a cos(h (omega tau - 2 pi gamma) + phi)
            terms.append((h, a * math.cos(psi), a * math.sin(psi)))
        out[j] = tuple(terms)
    return out


def mesh_frequency_of_speed(ps) -> float | None:
    """The mesh frequency (Hz) the carrier's speed gives where the ring alone is held and
    its teeth are known, ``Z_r n_c / 60`` (the tooth-pass frequency seen from the carrier);
    else None."""
    held = [j for j in ("carrier", "ring", "sun") if ps.members[j].torsional > 0]
    if ps.ring_teeth is None or held != ["ring"]:
        return None
    return ps.ring_teeth * abs(ps.carrier_speed_rpm) / 60.0


def derive_dynamics(st: PlanetaryStructure) -> PlanetaryDynamics:
    """The nonlinear model of ``st`` (module docstring); ``InputError`` where it cannot
    be built (no ``[planetary.dynamics]``, two rigid-body modes)."""
    ps = st.planetary
    needs_dynamics(ps)
    d = ps.dynamics
    names, kinds = st.springs, st.kinds
    _, _, phi = _pivot(st)
    ref = next(j for j, kind in enumerate(kinds) if kind == "mesh" and names[j][0] == "s")
    bodies = Bodies(
        physical=st.physical,
        mass=st.mass,
        springs=names,
        kinds=kinds,
        incidence=st.incidence,
        stiffness=st.stiffness,
        rigid_body_modes=st.rigid_body_modes,
        half_backlash_m={
            j: d.backlash_sun if names[j].startswith("s") else d.backlash_ring
            for j, kind in enumerate(kinds)
            if kind == "mesh"
        },
        waves=_variation(st),
        labels={
            j: "sun-planet" if names[j].startswith("s") else "ring-planet"
            for j, kind in enumerate(kinds)
            if kind == "mesh"
        },
        # the load: F_s on u_s, the carrier's reaction where the set can turn as a whole
        load=_load(st, phi),
        reference=ref,
    )
    scale = scales(st)
    frame = _frame(st)
    if frame is not None:
        _definite(st)
    bodies = replace(bodies, errors=_errors(st), frame=frame)
    return BodyDynamics(
        structure=st,
        name=ps.name,
        description=ps.description,
        source=str(ps.source),
        title="planetary set",
        parameters=(("omega", scale["omega"]), ("f_s", scale["f_s"]), ("zeta", d.damping_ratio)),
        physical=(
            ("mesh_frequency_hz", "omega", "hz", "positive", "the mesh frequency in Hz"),
            ("sun_force_N", "f_s", "force", "positive", "the sun's force on its base circle in N"),
            ("damping_ratio", "zeta", 1.0, "unit", "the damping ratio"),
        ),
        # a turning carrier's speed, which the frame's terms keep whatever mesh frequency
        # a run sets, and the mesh frequency it gives itself (numbers only: commands note
        # runs at other mesh frequencies)
        data={
            "frame": {
                "carrier_speed_rpm": float(ps.carrier_speed_rpm),
                "mesh_frequency_of_speed_hz": mesh_frequency_of_speed(ps),
            }
        }
        if frame is not None
        else {},
        **build(bodies, ("omega", "f_s", "zeta")),
    )
