"""``SweepPoint``: the public name of one sweep point, kept for ``gearsym.SweepPoint``.

A sweep point is a classified run like any other: :class:`~..analysis.record.RunRecord`
(its values hold the swept parameter's value, ``point.value``).
"""

from __future__ import annotations

from ..analysis.record import Extremes, RunRecord

__all__ = ["Extremes", "SweepPoint"]

SweepPoint = RunRecord
