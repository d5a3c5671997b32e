"""One sweep point as a typed object: what the sweep store keeps and every caller reads.

:meth:`SweepPoint.to_dict` is the stored (and ``sweep.json``) form; :meth:`from_dict`
reads it back, so a point survives a process boundary and a resumed sweep unchanged.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..analysis.classify import Classification

__all__ = ["Extremes", "SweepPoint"]


@dataclass(frozen=True)
class Extremes:
    """Max and min of one state over the sampled window (None when nothing finite)."""

    max: float | None
    min: float | None

    def to_dict(self) -> dict:
        return {"max": self.max, "min": self.min}


@dataclass(frozen=True)
class SweepPoint:
    """The summary of one operating point of a sweep.

    Attributes
    ----------
    value : float
        The swept parameter's value.
    status : str
        ``ok``, ``divergent``, ``invalid`` or ``failed`` (then ``error`` says why).
    classification : dict
        coordinate -> :class:`Classification` (motion, period, evidence).
    extremes : dict
        state -> :class:`Extremes` over the sampled window.
    poincare : dict
        state -> its Poincare points, ndarray (periods,).
    x_final : ndarray or None
        The end state, from which a continued sweep starts its next point.
    meshing_states, lyapunov, spectra, integration : dict
        Meshing-state shares, the exponent's summary (None if not computed), spectral
        peaks per coordinate, and the integration record.
    """

    value: float
    status: str
    classification: dict
    extremes: dict
    meshing_states: dict = field(default_factory=dict)
    lyapunov: dict | None = None
    spectra: dict = field(default_factory=dict)
    poincare: dict = field(default_factory=dict)
    x_final: np.ndarray | None = None
    integration: dict = field(default_factory=dict)
    error: str | None = None
    attempts: int | None = None

    @classmethod
    def from_result(cls, result, value: float) -> SweepPoint:
        """The summary of a :class:`~gearsym.solver.analysis.point.PointResult`."""
        d = result.describe(poincare=False)  # the arrays are copied below
        tr = result.trajectory
        return cls(
            value=float(value),
            status=d["integration"]["status"],
            classification=dict(result.classification),
            extremes={s: Extremes(e["max"], e["min"]) for s, e in d["extremes"].items()},
            meshing_states=d["meshing_states"],
            lyapunov=d["lyapunov"],
            spectra=d["spectra"],
            poincare={s: tr.poincare[k].copy() for k, s in enumerate(tr.system.states)},
            x_final=tr.x_final.copy(),
            integration=d["integration"],
        )

    @classmethod
    def failed(cls, system, value: float, error: Exception, attempts: int) -> SweepPoint:
        """A point whose integration failed: recorded with its error, never dropped."""
        why = {"error": str(error)}
        return cls(
            value=float(value),
            status="failed",
            classification={c: Classification("failed", None, why) for c in system.coordinates},
            extremes={s: Extremes(None, None) for s in system.states},
            poincare={s: np.zeros(0) for s in system.states},
            error=str(error),
            attempts=attempts,
        )

    # -- what callers ask ---------------------------------------------------------------
    @property
    def ok(self) -> bool:
        return self.status == "ok"

    def motion(self, coordinate: str) -> str:
        return self.classification[coordinate].motion

    def max(self, state: str) -> float:
        """Max of ``state`` over the window; NaN for a failed point."""
        v = self.extremes[state].max
        return float("nan") if v is None else float(v)

    def min(self, state: str) -> float:
        """Min of ``state`` over the window; NaN for a failed point."""
        v = self.extremes[state].min
        return float("nan") if v is None else float(v)

    def poincare_state(self, states) -> np.ndarray:
        """The first Poincare point as a state vector, in the order of ``states``."""
        return np.array([self.poincare[s][0] for s in states])

    @property
    def lyapunov_exponent(self) -> float | None:
        return None if self.lyapunov is None else self.lyapunov["exponent"]

    # -- storage --------------------------------------------------------------------------
    def to_dict(self) -> dict:
        out = {"value": self.value, "status": self.status}
        if self.status == "failed":
            out["error"] = self.error
        out["classification"] = {c: k.describe() for c, k in self.classification.items()}
        out["extremes"] = {s: e.to_dict() for s, e in self.extremes.items()}
        out["meshing_states"] = self.meshing_states
        out["lyapunov"] = self.lyapunov
        out["spectra"] = self.spectra
        out["poincare"] = {s: np.asarray(v).tolist() for s, v in self.poincare.items()}
        out["x_final"] = None if self.x_final is None else np.asarray(self.x_final).tolist()
        out["integration"] = self.integration
        if self.attempts is not None:
            out["attempts"] = self.attempts
        return out

    @classmethod
    def from_dict(cls, d: dict) -> SweepPoint:
        return cls(
            value=float(d["value"]),
            status=d["status"],
            classification={
                c: Classification(k["motion"], k["period"], k["evidence"])
                for c, k in d["classification"].items()
            },
            extremes={s: Extremes(e["max"], e["min"]) for s, e in d["extremes"].items()},
            meshing_states=d.get("meshing_states", {}),
            lyapunov=d.get("lyapunov"),
            spectra=d.get("spectra", {}),
            poincare={s: np.asarray(v, dtype=float) for s, v in d["poincare"].items()},
            x_final=None if d.get("x_final") is None else np.asarray(d["x_final"], dtype=float),
            integration=d.get("integration", {}),
            error=d.get("error"),
            attempts=d.get("attempts"),
        )
