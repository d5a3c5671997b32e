"""The arrays of a ``STRUCTURE`` mapping that the linear analyses share (``modes``,
``parametric``, ``forced``): the masses and springs, and a turning carrier's terms.

A set whose carrier turns at ``W`` (the mapping's ``carrier_speed_rad_s``) adds the
gyroscopic ``W G`` to the damping and the centripetal ``-W^2 K_Omega`` to the stiffness
(Lin and Parker, 1999; ``derive/equations/planetary.py`` assembles ``G`` and ``K_Omega``).
"""

from __future__ import annotations

import numpy as np

__all__ = ["frame_terms", "springs", "stiffness"]


def springs(structure: dict) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(mass, R, k)`` of a ``STRUCTURE`` mapping, as float arrays."""
    return tuple(np.asarray(structure[key], float) for key in ("mass", "incidence", "stiffness"))


def frame_terms(structure: dict) -> tuple[np.ndarray, np.ndarray]:
    """``(W^2 K_Omega, W G)`` of a turning carrier (zeros without one)."""
    n = len(structure["mass"])
    W = float(structure.get("carrier_speed_rad_s") or 0.0)
    if not W:
        return np.zeros((n, n)), np.zeros((n, n))
    G = np.asarray(structure["gyroscopic"], float)
    return W**2 * np.asarray(structure["centripetal"], float), W * G


def stiffness(structure: dict) -> np.ndarray:
    """``K - W^2 K_Omega``: the springs' stiffness ``R^T diag(k) R`` less a turning
    carrier's centripetal terms (the stiffness itself without one)."""
    _, R, k = springs(structure)
    return R.T @ (k[:, None] * R) - frame_terms(structure)[0]
