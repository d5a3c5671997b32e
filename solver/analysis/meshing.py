"""Meshing state of each mesh, read from the sign of the model's own backlash force.

The teeth are in forward contact where the backlash force ``g(u) > 0``, apart where
``g(u) = 0`` and in backward contact where ``g(u) < 0``; the model's contract states where
``g`` is zero and its sign between (``Contract.force_sign``).  For the exact dead zone
that is ``u > 1``, ``|u| <= 1`` and ``u < -1``.  The study's polynomial fit is zero only at
``u = 0, +-0.7701``: it never separates, and inside the backlash gap ``|u| < 1`` it still
carries load (negative on ``(0, 0.7701)``, positive on ``(-0.7701, 0)``), which is reported
as its own share, not as separation.

Kahraman and Singh's regimes (1990, "Non-linear dynamics of a spur gear pair", J. Sound
Vib. 142) are read from a coordinate's extremes against the force's outer zeros.
"""

from __future__ import annotations

import numpy as np

from ..integrate import Trajectory

__all__ = [
    "GAP_LOADED_REGIMES",
    "REGIMES",
    "body_mesh_deflections",
    "contract_regimes",
    "loaded_sides",
    "meshing_regime",
    "meshing_states",
]

# Kahraman and Singh's regimes (a force that vanishes between its edges: a dead zone) and
# their counterparts for a force that only crosses zero there (nothing separates, nothing
# impacts: the force reverses inside the gap).
REGIMES = ("no impact", "single-sided impact", "double-sided impact", "no contact")
GAP_LOADED_REGIMES = (
    "no impact",
    "single-sided force reversal",
    "double-sided force reversal",
    "inside the outer zeros, loaded",
)


def meshing_regime(
    lo: float, hi: float, lower: float, upper: float, *, zero_between: bool = True
) -> str:
    """The meshing regime of a coordinate whose extremes over the window are ``lo, hi``.

    Parameters
    ----------
    lo, hi : float
        Minimum and maximum of the coordinate (half backlashes).
    lower, upper : float
        The outer zeros of the force (``lower <= upper``): ``g > 0`` beyond ``upper`` and
        ``g < 0`` below ``lower``.
    zero_between : bool
        True when ``g`` vanishes on all of ``[lower, upper]`` (the dead zone): the names
        of Kahraman and Singh (:data:`REGIMES`).  False when it only crosses zero there (a
        polynomial fit): the same reading named by what the force does
        (:data:`GAP_LOADED_REGIMES`).

    Returns
    -------
    str
        ``no impact`` (beyond one edge throughout: the force keeps its sign), the
        one-sided and two-sided regimes, the regime inside the edges, or
        ``undetermined`` for non-finite extremes.
    """
    if not (np.isfinite(lo) and np.isfinite(hi)):
        return "undetermined"
    names = REGIMES if zero_between else GAP_LOADED_REGIMES
    front, back = hi > upper, lo < lower
    if front and back:
        return names[2]
    if lo > upper or hi < lower:
        return names[0]
    if front or back:
        return names[1]
    return names[3]


def contract_regimes(contract, xmin, xmax) -> dict:
    """Coordinate -> :func:`meshing_regime` of each mesh with a force sign in
    ``contract``, from the window's extremes ``xmin``, ``xmax`` ((n,) by state index)."""
    out = {}
    for coord, sign in contract.force_sign.items():
        k = contract.index(coord)
        lower, upper = sign.edges
        out[coord] = meshing_regime(xmin[k], xmax[k], lower, upper, zero_between=sign.zero_between)
    return out


def meshing_states(tr: Trajectory) -> dict:
    """Share of the sampled time each mesh spends by the sign of its backlash force.

    Returns
    -------
    dict
        mesh -> ``{"forward": share with g(u) > 0, "separated": share with g(u) = 0,
        "backward": share with g(u) < 0}`` over the finite samples (None each when there
        are none); for a force law that is loaded inside the gap (every model but the dead
        zone) also ``"loaded_in_gap"``: the share inside the backlash gap
        (``lower < u < upper`` of the contract's ``contact``) with ``g(u) != 0``, time a
        dead zone would spend separated.  Coordinates without a force sign in the
        contract are left out.
    """
    if hasattr(tr.system.module, "mesh_deflections"):  # a model in body coordinates
        return _body_meshing(tr)
    out = {}
    c = tr.system.contract
    for coord in tr.system.coordinates:
        sign = c.force_sign.get(coord)
        if sign is None:
            continue
        u = tr.coordinate(coord)
        u = u[np.isfinite(u)]
        gap = c.contact.get(coord)
        loaded = gap is not None and _loaded_in(sign, *gap)
        if not u.size:
            out[coord] = dict.fromkeys(("forward", "separated", "backward"), None)
            if loaded:
                out[coord]["loaded_in_gap"] = None
            continue
        s = sign.sign(u)
        out[coord] = {
            "forward": float(np.mean(s > 0)),
            "separated": float(np.mean(s == 0)),
            "backward": float(np.mean(s < 0)),
        }
        if loaded:
            out[coord]["loaded_in_gap"] = float(np.mean((u > gap[0]) & (u < gap[1]) & (s != 0)))
    return out


def _loaded_in(sign, lower: float, upper: float) -> bool:
    """``g`` is nonzero somewhere in the open gap ``(lower, upper)``."""
    bounds = (-np.inf, *sign.zeros, np.inf)
    return any(
        s != 0 and a < upper and b > lower
        for s, a, b in zip(sign.signs, bounds[:-1], bounds[1:], strict=True)
    )


def loaded_sides(system) -> dict:
    """Each mesh's loaded flank of a model in body coordinates, as the sign of its
    deflection ``u`` there (+1: ``u > 1``): the sign in the linear static solution at the
    model's load, every mesh's teeth touching (``K ybar = f load``, the module's
    ``STATIC``), +1 where the mesh carries none.  A planetary set's sun force loads every
    mesh on ``u > 1``; a gear train's meshes can be loaded on either (the back-to-back
    rig's test pair on ``u < -1``), as the derivation's ``loaded_flanks`` finds them."""
    module = system.module
    static = module.STATIC
    # the load parameter follows omega in both kinds of model (f of a train, f_s of a set)
    y = np.linalg.lstsq(
        np.asarray(static["stiffness"]), system.p[1] * np.asarray(static["load"]), rcond=None
    )[0]
    u = {mesh: float(np.dot(d["row"], y)) for mesh, d in module.MESHES.items()}
    small = 1e-12 * max(1e-300, max(map(abs, u.values()), default=0.0))
    return {mesh: -1 if v < -small else 1 for mesh, v in u.items()}


def body_mesh_deflections(tr: Trajectory) -> dict:
    """Each mesh's deflection in its half backlashes over trajectory ``tr`` of a model in
    body coordinates, its transmission error included where it has one (a train's mesh):
    ``{mesh: (K,)}``, what its force law reads."""
    module = tr.system.module
    omega = tr.system.p[list(module.PARAMETERS).index("omega")]
    tau = np.asarray(tr.t, dtype=float)
    out = {}
    for mesh, u in module.mesh_deflections(tr.x).items():
        out[mesh] = np.asarray(u, dtype=float) + sum(
            c * np.cos(h * omega * tau) + s * np.sin(h * omega * tau)
            for h, c, s in module.MESHES[mesh].get("error", ())
        )
    return out


def _body_meshing(tr: Trajectory) -> dict:
    sides = loaded_sides(tr.system)
    out = {}
    for mesh, u in body_mesh_deflections(tr).items():
        u = sides[mesh] * u[np.isfinite(u)]
        if not u.size:
            out[mesh] = dict.fromkeys(("forward", "separated", "backward"), None)
            continue
        out[mesh] = {
            "forward": float(np.mean(u > 1.0)),
            "separated": float(np.mean(np.abs(u) <= 1.0)),
            "backward": float(np.mean(u < -1.0)),
        }
    return out
