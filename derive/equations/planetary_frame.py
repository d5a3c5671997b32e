"""The carrier's rotating frame of a planetary set's linear model: the gyroscopic matrix
``G`` and the centripetal ``K_Omega`` at a carrier speed (``planetary.py``'s module text
gives the terms and the load term on ``u_c``), and the checks a speed must pass.

:func:`at_speed` puts a derived set at any carrier speed without deriving it again (the
deflections and ``R`` do not depend on the speed): ``derive_planetary`` takes it for the
file's ``carrier_speed_rpm``, the carrier-speed sweep (``gearsym modes SET --speeds``) for
each of its speeds.
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from ..input.planetary import balanced, bearing_limit_rpm

__all__ = ["at_speed", "rotating_frame"]

_PAIRS = (("x_c", "y_c"), ("x_r", "y_r"), ("x_s", "y_s"))


def rotating_frame(
    names: list[str], mass: list[float], speed: float, bearing: float
) -> tuple[np.ndarray, np.ndarray]:
    """``(G, K_Omega)`` over the coordinates ``names`` at the carrier speed ``speed``
    (rad/s) with the planets' bearing stiffness ``bearing``: every body's pair of
    translations, ``x_j, y_j`` or ``zeta_n, eta_n``, and the planets' bearing load on
    ``u_c``."""
    G = np.zeros((len(names), len(names)))
    K = np.zeros_like(G)
    pairs = list(_PAIRS)
    pairs += [(n, "eta_" + n[len("zeta_") :]) for n in names if n.startswith("zeta_")]
    for a, b in pairs:
        i, j = names.index(a), names.index(b)
        G[i, j], G[j, i] = -2.0 * mass[i], 2.0 * mass[j]
        K[i, i], K[j, j] = mass[i], mass[j]
    # the planets' bearings' centripetal load through the pins' second-order motion
    planets = [mass[names.index(n)] for n in names if n.startswith("zeta_")]
    K[names.index("u_c"), names.index("u_c")] -= sum(
        bearing * m / (bearing - m * speed**2) for m in planets
    )
    return G, K


def at_speed(st, rpm: float):
    """The derived set ``st`` (a ``PlanetaryStructure``) with its carrier turning at
    ``rpm``: the rotating frame's ``G`` and ``K_Omega`` for it (none at 0).  Raises
    ``ValueError`` for a speed the model does not take (the torsional model, unbalanced
    planets, the bearings' limit) and ``InputError`` where the meshes would share the
    planets' centripetal load."""
    ps = st.planetary
    if rpm == 0:
        return replace(
            st,
            planetary=replace(ps, carrier_speed_rpm=0.0),
            carrier_speed_rad_s=0.0,
            gyroscopic=None,
            centripetal=None,
        )
    if ps.dofs == "torsional":
        raise ValueError("a carrier speed needs the lateral-torsional model (translations)")
    if not balanced(ps.angles_deg):
        raise ValueError(
            "a carrier speed needs balanced planets (equally spaced, or in opposite pairs)"
        )
    speed = rpm * 2.0 * math.pi / 60.0
    bearing = ps.members["planet"].bearing
    if abs(rpm) >= bearing_limit_rpm(ps.members["planet"]):
        raise ValueError(
            f"at a carrier speed of {rpm:g} rpm the planets' bearings ({bearing:g} N/m) "
            "cannot hold the planets against the centripetal stiffness m_p Omega_c^2 = "
            f"{ps.members['planet'].mass * speed**2:.4g} N/m"
        )
    names, mass = list(st.physical), list(st.mass)
    G, K_omega = rotating_frame(names, mass, speed, bearing)
    _bearings_carry_the_load(ps, names, mass, st.incidence, st.stiffness, st.kinds, speed, K_omega)
    return replace(
        st,
        planetary=replace(ps, carrier_speed_rpm=float(rpm)),
        carrier_speed_rad_s=speed,
        gyroscopic=G,
        centripetal=K_omega,
    )


def _bearings_carry_the_load(ps, names, mass, R, k, kinds, speed, K_omega) -> None:
    """Refuse a set whose meshes would share the planets' steady centripetal load (all its
    members held and unequal pressure angles): the load term on ``u_c`` assumes the
    planets' bearings carry all of it, and the geometric stiffness of a mesh's preload is
    not modelled.  The static deflection under ``m_p Omega_c^2`` on each ``zeta`` (per unit
    ``r_c``), and the mesh forces against the bearing forces in it."""
    from ..input.reader import InputError

    K = R.T @ (np.asarray(k)[:, None] * R) - speed**2 * K_omega
    load = np.array(
        [m * speed**2 if n.startswith("zeta_") else 0.0 for n, m in zip(names, mass, strict=True)]
    )
    q = np.linalg.lstsq(K, load, rcond=None)[0]
    force = np.abs(np.asarray(k) * (R @ q))
    mesh = max(f for f, kind in zip(force, kinds, strict=True) if kind == "mesh")
    carried = max(f for f, kind in zip(force, kinds, strict=True) if kind == "planet bearing")
    if mesh > 1e-9 * carried:
        raise InputError(
            ps.source,
            "planetary.carrier_speed_rpm",
            f"the meshes would carry {100 * mesh / (mesh + carried):.3g} % of the planets' "
            "centripetal load (the sun, ring and carrier all held, unequal pressure angles): "
            "the geometric stiffness of a mesh's preload is not modelled; free one member's "
            "rotation or give the two meshes one pressure angle",
        )
