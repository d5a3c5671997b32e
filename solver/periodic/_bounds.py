"""Where a continuation parameter may go: the valid range the model states for it.

A generated module states the valid range of each scene parameter as data,
``SCENE_PARAMETER_LIMITS = {name: (low, high, low excluded)}`` (``derive/input/scene.py``),
and the System requires the forcing frequency to be > 0.  A continuation reads them
here, before it steps: a predictor that would cross a boundary is shortened to land on
it (an excluded end: a thousandth of the range inside it, where the model is still
defined and the forcing period finite), and the branch stops there, saying so, with the
points computed so far kept.  Model parameters without a stated range are bounded by what
``parameters()`` accepts (a stiffness that turns negative, for one): a step the model
refuses is shortened like a failed correction, and the branch stops where it cannot go on.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

__all__ = ["Interval", "interval_of"]


@dataclass(frozen=True)
class Interval:
    """The valid values of one parameter: ``low <= v <= high`` (``low < v`` when
    ``low_open``); infinite ends where the model states none."""

    name: str
    low: float = -math.inf
    high: float = math.inf
    low_open: bool = False

    def __contains__(self, value: float) -> bool:
        v = float(value)
        if not math.isfinite(v) or v > self.high:
            return False
        return v > self.low if self.low_open else v >= self.low

    def rule(self) -> str:
        """The range as a reader writes it: ``omega > 0``, ``damping_ratio in [0, 1]``."""
        low, high = math.isfinite(self.low), math.isfinite(self.high)
        if low and high:
            return f"{self.name} in {'(' if self.low_open else '['}{self.low:g}, {self.high:g}]"
        if low:
            return f"{self.name} {'>' if self.low_open else '>='} {self.low:g}"
        if high:
            return f"{self.name} <= {self.high:g}"
        return f"{self.name}: any finite value"

    def ends(self, start: float, stop: float) -> tuple[float, float]:
        """``[min, max]`` of ``start`` and ``stop`` cut to the valid range; an excluded
        end is kept a thousandth of the range inside (never past ``start``)."""
        lo, hi = min(start, stop), max(start, stop)
        if lo < self.low or (self.low_open and lo <= self.low):
            margin = 1e-3 * (hi - self.low) if self.low_open else 0.0
            lo = min(self.low + margin, start)
        return lo, min(hi, self.high)

    def is_end(self, value: float) -> bool:
        """``value`` is an included end of the valid range (``damping_ratio = 0``)."""
        return value == self.high or (value == self.low and not self.low_open)


def interval_of(system, name: str) -> Interval:
    """The valid range of ``name`` (a scene or model parameter of ``system``'s model), as
    the model states it; ``KeyError`` for a name that is neither."""
    module = system.module
    scene = getattr(module, "SCENE_PARAMETERS", {})
    physical = getattr(module, "PHYSICAL", {})
    aliases = getattr(module, "PHYSICAL_ALIASES", {})
    if name not in scene and name not in system.contract.parameters and name not in physical:
        if name not in aliases:
            more = f"; physical: {', '.join([*physical, *aliases])}" if physical else ""
            raise KeyError(
                f"no parameter '{name}'; scene parameters: {', '.join(sorted(scene))}; model "
                f"parameters: {', '.join(system.contract.parameters)}{more}"
            )
    low, high, low_open = -math.inf, math.inf, False
    limits = getattr(module, "PHYSICAL_LIMITS", {})
    stated = getattr(module, "SCENE_PARAMETER_LIMITS", {}).get(name) or limits.get(
        (aliases.get(name) or (name,))[0]
    )
    if stated is not None:
        low, high, low_open = stated
        low = -math.inf if low is None else float(low)
        high = math.inf if high is None else float(high)
    if name == system.contract.forcing_frequency and not low > 0:
        low, low_open = 0.0, True  # System: the excitation frequency must be > 0
    return Interval(name, low, high, bool(low_open))
