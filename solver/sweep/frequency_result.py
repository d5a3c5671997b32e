"""What a frequency response gives: one :class:`Curve` per method, gathered in a
:class:`FrequencyResponse` (``frequency.py`` computes them)."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..system import System

__all__ = ["QUANTITIES", "Curve", "FrequencyResponse"]

# What each record keeps per coordinate (and the dynamic factor where the model emits its
# mesh forces): the extremes too, since impact regimes are read from them (|u| > 1:
# contact, u < -1: back contact).
QUANTITIES = ("mean", "amplitude", "rms", "min", "max")


@dataclass(frozen=True)
class Curve:
    """One method's solution curve: per point the parameter value, stability and, per
    coordinate, mean, amplitude (half peak-to-peak), RMS, minimum and maximum (harmonic
    balance: at the refined extrema of the trigonometric polynomial; shooting and
    integration: over the samples); the located events."""

    method: str
    parameter: str
    values: np.ndarray
    stable: np.ndarray
    stats: dict  # coordinate -> {"mean", "amplitude", "rms", "max", "min",
    # "dynamic_factor"}: arrays
    events: tuple = ()  # the Bifurcation records located on the branch (records.py)
    wall_time: float = 0.0
    details: dict = field(default_factory=dict)
    # the state at tau = 0 (mod n T) of each point (harmonic balance, shooting), kept for
    # checks and restarts; not written to the result files
    states: tuple = ()

    def records(self) -> list[dict]:
        out = []
        for k, v in enumerate(self.values):
            rec = {"method": self.method, self.parameter: float(v), "stable": bool(self.stable[k])}
            if "direction" in self.details:
                rec["direction"] = self.details["direction"]
            for c, s in self.stats.items():
                rec[c] = {q: float(s[q][k]) for q in QUANTITIES}
                if "dynamic_factor" in s:
                    rec[c]["dynamic_factor"] = float(s["dynamic_factor"][k])
            out.append(rec)
        return out


@dataclass(frozen=True)
class FrequencyResponse:
    system: System
    parameter: str
    start: float
    stop: float
    curves: tuple[Curve, ...]

    def records(self) -> list[dict]:
        """Every point of every curve, each with its curve's index in ``curves`` (one
        method may give two: harmonic balance from both ends of a range it turned out of)."""
        out = [r | {"curve": k} for k, c in enumerate(self.curves) for r in c.records()]
        if not self.system.contract.provides("mesh_force", "static_mesh_force"):
            # no mesh forces, no dynamic factor (not a null for every body coordinate)
            for r in out:
                for c in self.system.coordinates:
                    r[c].pop("dynamic_factor", None)
        return out

    def _curves_text(self) -> str:
        return ", ".join(f"{c.method} {len(c.values)}" for c in self.curves)

    def __repr__(self) -> str:
        return (
            f"FrequencyResponse({self.system!r}: {self.parameter} {self.start:.4g} to "
            f"{self.stop:.4g}; points per method: {self._curves_text()})"
        )

    def summary(self) -> str:
        """A few lines: per method its points, stable share, events and the peak
        amplitude of each coordinate (half backlashes)."""
        lines = [f"frequency response of {self.system!r} over {self.parameter}"]
        for c in self.curves:
            peaks = ", ".join(
                f"{k} {np.nanmax(s['amplitude']):.4g}" if len(c.values) else k
                for k, s in c.stats.items()
            )
            events = ", ".join(f"{e.name} at {e.value:.4g}" for e in c.events[:4])
            more = f" (+{len(c.events) - 4})" if len(c.events) > 4 else ""
            lines.append(
                f"  {c.method}: {len(c.values)} points, {int(np.sum(c.stable))} stable, "
                f"peak amplitude {peaks}; events: {events or 'none'}{more}; {c.wall_time:.1f} s"
            )
        return "\n".join(lines)

    def to_dict(self) -> dict:
        from ..provenance import provenance

        return provenance(self.system) | {
            "parameter": self.parameter,
            "range": [self.start, self.stop],
            "curves": [
                {
                    "method": c.method,
                    "curve": k,
                    "points": len(c.values),
                    "wall_time_s": c.wall_time,
                    "events": [e.to_dict() for e in c.events],
                    **c.details,
                }
                for k, c in enumerate(self.curves)
            ],
            "records": self.records(),
        }

    def to_table(self) -> tuple[list, list]:
        coords = self.system.coordinates
        # the dynamic factor where the model emits its mesh forces (its coordinates are
        # its meshes); a model in body coordinates has none, not a column of blanks
        provides = self.system.contract.provides("mesh_force", "static_mesh_force")
        quantities = (*QUANTITIES, "dynamic_factor") if provides else QUANTITIES
        columns = ["method", "curve", self.parameter, "stable"] + [
            f"{c}_{q}" for c in coords for q in quantities
        ]
        rows = []
        for r in self.records():
            method = r["method"] + (f" {r['direction']}" if "direction" in r else "")
            rows.append(
                [method, r["curve"], r[self.parameter], r["stable"]]
                + [r[c].get(q, float("nan")) for c in coords for q in quantities]
            )
        return columns, rows

    def save(self, path, **extra):
        """Write to ``path``: ``.json``, ``.csv`` or ``.mat`` (see ``solver/export.py``)."""
        from ..export import save

        return save(self, path, **extra)
