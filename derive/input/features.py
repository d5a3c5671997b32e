"""A scene's ``[features]``: which terms the model carries.

* ``stiffness_harmonics`` -- how many harmonics of each mesh stiffness to keep (0 gives
  constant stiffness and no time-varying stiffness code);
* ``backlash`` -- ``linear``, ``dead-zone`` (the default: the exact dead zone, force zero
  for ``|x| <= 1``), ``smooth`` or ``polynomial`` (the reference study's fit, with
  ``backlash_order``, ``backlash_range``, ``backlash_step``; or ``backlash_width``), built
  through one registry of the backlash kinds (``derive/mesh/backlash.py``).  The
  polynomial is zero at ``x = 0, +-0.770`` and carries load inside the gap, so a
  user's gears get the dead zone unless the scene states ``backlash = "polynomial"``
  (the reference scenes do, as the study states its 7th-order fit);
* ``transmission_error``, ``mesh_phase``, ``damping_coupling`` -- on or off;
* ``degrees_of_freedom`` -- torsional, or beyond (``derive/equations/structure.py``).
"""

from __future__ import annotations

from dataclasses import dataclass, field

from ..mesh.backlash import (
    BACKLASH_MODELS,
    Backlash,
    DeadZone,
    LinearContact,
    SmoothDeadZone,
    fit_dead_zone,
)
from .reader import Table

__all__ = ["BACKLASH_KEYS", "Features", "parse_features"]


@dataclass(frozen=True)
class Features:
    """Which terms the model carries (the defaults are a scene's: the exact dead zone)."""

    stiffness_harmonics: int = 3
    backlash: Backlash = field(default_factory=DeadZone)
    transmission_error: bool = True
    mesh_phase: bool = True
    damping_coupling: bool = True
    # Which degrees of freedom each gear has (derive/equations/structure.py DEGREES_OF_FREEDOM).
    degrees_of_freedom: str = "torsional"

    def flags(self) -> dict:
        """The feature switches, with the backlash by kind only (the degrees of freedom
        only when they go beyond torsion, so that torsional models keep their files)."""
        flags = {
            "stiffness_harmonics": self.stiffness_harmonics,
            "backlash": self.backlash.kind,
            "transmission_error": self.transmission_error,
            "mesh_phase": self.mesh_phase,
            "damping_coupling": self.damping_coupling,
        }
        if self.degrees_of_freedom != "torsional":
            flags["degrees_of_freedom"] = self.degrees_of_freedom
        return flags

    def describe(self) -> dict:
        """The feature switches with the backlash model's full description."""
        return self.flags() | {"backlash": self.backlash.describe()}


def _polynomial(t: Table) -> Backlash:
    order = t.integer("backlash_order", 7)
    if order % 2 == 0:
        raise t.error("backlash_order", f"must be odd (the dead zone is odd), got {order}")
    fit_range = t.number("backlash_range", 3.0)
    step = t.number("backlash_step", 0.01, low=0.0)
    try:
        return fit_dead_zone(order, fit_range, step if step > 0 else None)
    except ValueError as err:
        key = {"order": "backlash_order", "range": "backlash_range"}.get(
            str(err).split(" ", 1)[0], "backlash_step"
        )
        raise t.error(key, str(err)) from None


# Registry: backlash kind -> (the keys it reads, how it is built from the [features] table).
_BACKLASH_BUILDERS = {
    "linear": ((), lambda t: LinearContact()),
    "dead-zone": ((), lambda t: DeadZone()),
    "smooth": (
        ("backlash_width",),
        lambda t: SmoothDeadZone(t.number("backlash_width", 0.05, low=0, low_open=True, high=1.0)),
    ),
    "polynomial": (("backlash_order", "backlash_range", "backlash_step"), _polynomial),
}
assert set(_BACKLASH_BUILDERS) == set(BACKLASH_MODELS)
# The keys each backlash kind reads (scene.variant drops those of the other kinds).
BACKLASH_KEYS = {kind: keys for kind, (keys, _) in _BACKLASH_BUILDERS.items()}


def parse_features(t: Table | None) -> Features:
    """The ``[features]`` table ``t`` (None: every default), checked."""
    if t is None:
        return Features()
    harmonics = t.integer("stiffness_harmonics", 3, low=0, high=64)
    kind = t.string("backlash", "dead-zone", choices=tuple(BACKLASH_MODELS))
    for other, (keys, _) in _BACKLASH_BUILDERS.items():
        for key in keys:
            if other != kind and key in t.data:
                raise t.error(key, f"applies to backlash = '{other}' only, not '{kind}'")
    backlash = _BACKLASH_BUILDERS[kind][1](t)
    features = Features(
        stiffness_harmonics=harmonics,
        backlash=backlash,
        transmission_error=t.boolean("transmission_error", True),
        mesh_phase=t.boolean("mesh_phase", True),
        damping_coupling=t.boolean("damping_coupling", True),
        degrees_of_freedom=_degrees_of_freedom(t),
    )
    t.finish()
    return features


def _degrees_of_freedom(t: Table) -> str:
    from ..equations.structure import DEGREES_OF_FREEDOM

    dofs = t.string("degrees_of_freedom", "torsional", choices=tuple(DEGREES_OF_FREEDOM))
    if dofs != "torsional" and not t.data.get("damping_coupling", True):
        raise t.error(
            "damping_coupling",
            f"must stay true with degrees_of_freedom = '{dofs}': a mesh's damper acts on a "
            "deflection its gears' translations share",
        )
    return dofs
