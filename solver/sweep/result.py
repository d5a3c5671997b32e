"""The result of a sweep: one :class:`~..analysis.record.RunRecord` per value, in order.

``save`` writes JSON, CSV or MATLAB files (``solver/export.py``).  A sweep that ran with a
store already holds every point's JSON text (written once, in the worker that computed
the point); ``sweep.json`` is then assembled from those texts instead of encoding the
4 MB of Poincare points a second time.
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .._json import dumps
from ..analysis.record import RunRecord
from .store import write_atomic

__all__ = ["SweepResult"]


@dataclass(frozen=True)
class SweepResult:
    """Per-point summaries of a sweep (in the order of ``values``)."""

    model: str
    model_hash: str
    parameter: str
    values: np.ndarray
    direction: str  # "forward", "backward" or "independent"
    base_values: dict
    settings: dict
    points: list = field(default_factory=list)  # RunRecord, in the order of values
    scales: dict = field(default_factory=dict)  # omega_n and half backlash: back to SI
    # Each point's JSON text, dumps(point.to_dict()), when the store already wrote it.
    texts: list | None = field(default=None, compare=False, repr=False)
    resumed: int = field(default=0, compare=False)  # points that came from the store

    def poincare(self, state: str) -> list[np.ndarray]:
        return [np.asarray(p.poincare[state]) for p in self.points]

    def motion(self, coordinate: str) -> list[str]:
        return [p.motion(coordinate) for p in self.points]

    def maxima(self, state: str) -> np.ndarray:
        """Max of ``state`` at every point (NaN where a point failed)."""
        return np.array([p.max(state) for p in self.points])

    def minima(self, state: str) -> np.ndarray:
        """Min of ``state`` at every point (NaN where a point failed)."""
        return np.array([p.min(state) for p in self.points])

    def _motions(self, most: int | None = None) -> str:
        """``period-1 at 4, chaotic at 2``: the attractor's motion (the first coordinate's
        verdict, which every coordinate shares) or a failed run's status; ``most`` kinds."""
        from collections import Counter

        counts = Counter(
            p.motion(next(iter(p.classification))) if p.ok else p.status for p in self.points
        )
        shown = counts.most_common(most)
        more = len(counts) - len(shown)
        return ", ".join(f"{m} at {k}" for m, k in shown) + (f", {more} more" if more else "")

    def _what(self) -> str:
        v = self.values
        span = f"{v[0]:.4g} to {v[-1]:.4g}" if len(v) else "no values"
        return f"{self.model}: {self.parameter} {span}, {len(self.points)} points, {self.direction}"

    def __repr__(self) -> str:
        return f"SweepResult({self._what()}; {self._motions(3)})"

    def summary(self) -> str:
        """A few lines: what was swept, the motions found and where each one ran."""
        lines = [f"sweep of {self._what()}", f"motions: {self._motions() or 'none'}"]
        runs, last = [], None
        for value, p in zip(self.values, self.points, strict=False):
            m = p.motion(next(iter(p.classification))) if p.ok else p.status
            if m != last:
                runs.append([m, value, value])
                last = m
            runs[-1][2] = value
        shown = [f"{m} {a:.4g} to {b:.4g}" if a != b else f"{m} {a:.4g}" for m, a, b in runs]
        lines.append(f"along {self.parameter}: " + "; ".join(shown[:8]))
        if len(shown) > 8:
            lines[-1] += f"; ... ({len(shown) - 8} more runs of one motion)"
        shown = {k: v for k, v in self.settings.items() if k != "x0" and v is not None}
        lines.append("settings: " + ", ".join(f"{k} = {v}" for k, v in shown.items()))
        return "\n".join(lines)

    def _head(self, **extra) -> dict:
        """Everything of :meth:`to_dict` but the points: the header block
        (``provenance.header``; ``overrides`` are ``base_values``), then the sweep."""
        from ..provenance import header

        return header(self.model, self.model_hash, self.scales, self.base_values, **extra) | {
            "parameter": self.parameter,
            "values": self.values.tolist(),
            "direction": self.direction,
            "settings": self.settings,
        }

    def to_dict(self) -> dict:
        return {**self._head(), "points": [p.to_dict() for p in self.points]}

    def to_table(self) -> tuple[list, list]:
        """One row per point: the value, status, motion of each coordinate, max and min of
        each state, and the largest Lyapunov exponent."""
        if not self.points:
            return [self.parameter, "status"], []
        coords = list(self.points[0].classification)
        states = list(self.points[0].extremes)
        columns = [
            self.parameter,
            "status",
            *(f"motion_{c}" for c in coords),
            *(f"{k}_{s}" for s in states for k in ("max", "min")),
            "lyapunov",
        ]
        rows = [
            [
                p.value,
                p.status,
                *(p.motion(c) for c in coords),
                *(f(s) for s in states for f in (p.max, p.min)),
                p.lyapunov_exponent,
            ]
            for p in self.points
        ]
        return columns, rows

    def poincare_table(self) -> tuple[list, list]:
        """The Poincare points as one long table (the bifurcation diagram's data): one
        row per point and sampled period, the parameter's value, the point's index in
        ``values``, the period's index in its sampled window and every state, as
        ``points[i].poincare`` holds them (a point that stopped early: the periods it ran)."""
        states = list(self.points[0].poincare) if self.points else []
        rows: list = []
        for i, p in enumerate(self.points):
            cols = [np.asarray(p.poincare[s], dtype=float) for s in states]
            n = min((c.size for c in cols), default=0)
            block = np.column_stack([c[:n] for c in cols]).tolist() if n else []
            rows += [[float(p.value), i, k, *row] for k, row in enumerate(block)]
        return [self.parameter, "point", "period", *states], rows

    def save(self, path: Path, **extra) -> Path:
        """Write the sweep (parameter values, scales and model hash included): ``.json``,
        ``.csv`` or ``.mat`` (see ``solver/export.py``); ``extra`` adds header keys."""
        path = Path(path)
        if path.suffix.lower() == ".json" and self.texts is not None:
            write_atomic(path, self.to_json(**extra))
            return path
        from ..export import save

        return save(self, path, **extra)

    def to_json(self, **extra) -> str:
        """``dumps(self.to_dict())``, made from the points' stored texts when there are."""
        if self.texts is None or len(self.texts) != len(self.points):
            return dumps({**self._head(**extra), **self.to_dict()})
        # "points" is the last key and json.dumps nests without indentation: the document
        # is the head with the texts spliced into its empty list.
        head = dumps({**self._head(**extra), "points": []})
        return head[: -len("]}")] + ", ".join(self.texts) + "]}"

    @classmethod
    def load(cls, path: Path) -> SweepResult:
        """A sweep saved with ``save(... .json)``, by this version or an older one (whose
        points name their value ``value``)."""
        d = json.loads(Path(path).read_text(encoding="utf-8"))
        for p in d["points"]:  # before one record served every run: "value" alone
            p.setdefault("values", {d["parameter"]: p.get("value")})
        return cls(
            d["model"],
            d["model_hash"],
            d["parameter"],
            np.asarray(d["values"]),
            d["direction"],
            d["overrides"] if "overrides" in d else d["base_values"],
            d["settings"],
            [RunRecord.from_dict(p) for p in d["points"]],
            d.get("scales", {}),
        )
