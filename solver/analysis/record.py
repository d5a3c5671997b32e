"""The one record of a classified run: what sweeps, regime maps and their store keep.

A run is one initial state at one set of parameter values, integrated and classified.
:class:`RunRecord` holds what it showed -- the verdict per coordinate with its evidence
(``classify.py``), the extremes and Poincare points per state, the exponent's summary,
the meshing shares or regime, status and timings -- and nothing that needs the model to
be read back: :meth:`RunRecord.to_dict` is its stored (and ``sweep.json``) form, and
:meth:`RunRecord.from_dict` reads it back unchanged, across processes and resumed runs.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .classify import Classification

__all__ = ["Extremes", "RunRecord"]


@dataclass(frozen=True)
class Extremes:
    """Max and min of one state over the sampled window (None when nothing finite)."""

    max: float | None
    min: float | None

    def to_dict(self) -> dict:
        return {"max": self.max, "min": self.min}


def _floats(v) -> np.ndarray:
    """A stored list (None for a NaN written as null) as a float array."""
    return np.asarray(v, dtype=float)


@dataclass(frozen=True)
class RunRecord:
    """One classified run (non-dimensional: states in half backlashes, time in 1/omega_n).

    Attributes
    ----------
    values : dict
        The parameter values that make this run (the swept one, or the two of a map).
    start : str
        Where it started: ``default`` (the loaded rest state), ``given``, ``continued``
        (the previous run's end state), ``forward``, ``backward`` or ``random-k``.
    x0 : ndarray (n,) or None
        The initial state; None: the default one.
    status : str
        ``ok``, ``divergent``, ``invalid`` or ``failed`` (then ``error`` says why).
    classification : dict
        coordinate -> :class:`Classification`: the attractor's motion and period, and the
        coordinate's own spread as evidence.
    verdict : dict or None
        The attractor's verdict with all its evidence (``verdict.Verdict.describe``:
        motion, period, periods run, the shooting check or each window's exponent and
        0-1 test); None for runs classified before verdicts were per attractor.
    extremes : dict
        state -> :class:`Extremes` over the sampled window.
    poincare : dict
        state -> its Poincare points, ndarray (K,) in time order (a map run keeps its
        last 64).
    spread : dict
        coordinate -> max - min of its Poincare points over the whole window (map runs).
    x_final : ndarray (n,) or None
        The end state, from which a continued run starts.
    meshing_states : dict
        mesh -> share of time in forward contact, separated and backward contact.
    meshing_regime : dict
        mesh -> Kahraman and Singh's regime (map runs, ``attractors.meshing_regime``).
    lyapunov : dict or None
        The largest exponent's summary (``exponent``, ``uncertainty``, ...), per unit tau.
    spectra, integration : dict
        Spectral peaks per coordinate; the integration's record (method, tolerances,
        wall time).
    """

    values: dict
    status: str
    classification: dict
    extremes: dict
    start: str = "default"
    x0: np.ndarray | None = None
    meshing_states: dict = field(default_factory=dict)
    meshing_regime: dict = field(default_factory=dict)
    lyapunov: dict | None = None
    spectra: dict = field(default_factory=dict)
    poincare: dict = field(default_factory=dict)
    spread: dict = field(default_factory=dict)
    x_final: np.ndarray | None = None
    integration: dict = field(default_factory=dict)
    error: str | None = None
    attempts: int | None = None
    verdict: dict | None = None

    @classmethod
    def failed(cls, system, values: dict, error: Exception, attempts: int, **start) -> RunRecord:
        """A run whose integration failed: recorded with its error, never dropped."""
        why = {"error": str(error)}
        return cls(
            values=dict(values),
            status="failed",
            classification={c: Classification("failed", None, why) for c in system.coordinates},
            extremes={s: Extremes(None, None) for s in system.states},
            poincare={s: np.zeros(0) for s in system.states},
            error=str(error),
            attempts=attempts,
            **start,
        )

    # -- what callers ask ---------------------------------------------------------------
    @property
    def ok(self) -> bool:
        return self.status == "ok"

    @property
    def value(self) -> float:
        """The one parameter value of a sweep's run."""
        if len(self.values) != 1:
            raise ValueError(f"a run at {self.values}: name the parameter, values[name]")
        return next(iter(self.values.values()))

    def motion(self, coordinate: str) -> str:
        return self.classification[coordinate].motion

    def period(self, coordinate: str) -> int | None:
        return self.classification[coordinate].period

    def max(self, state: str) -> float:
        """Max of ``state`` over the window; NaN for a failed run."""
        v = self.extremes[state].max
        return float("nan") if v is None else float(v)

    def min(self, state: str) -> float:
        """Min of ``state`` over the window; NaN for a failed run."""
        v = self.extremes[state].min
        return float("nan") if v is None else float(v)

    @property
    def xmax(self) -> np.ndarray:
        """Max of every state, (n,), in the order of the states (NaN where none)."""
        return np.array([self.max(s) for s in self.extremes])

    @property
    def xmin(self) -> np.ndarray:
        """Min of every state, (n,), in the order of the states (NaN where none)."""
        return np.array([self.min(s) for s in self.extremes])

    @property
    def tail(self) -> np.ndarray:
        """The Poincare points as states, (K, n)."""
        return np.column_stack([np.asarray(v, dtype=float) for v in self.poincare.values()])

    def poincare_state(self, states) -> np.ndarray:
        """The first Poincare point as a state vector, in the order of ``states``."""
        return np.array([self.poincare[s][0] for s in states])

    @property
    def lyapunov_exponent(self) -> float | None:
        return None if self.lyapunov is None else self.lyapunov["exponent"]

    @property
    def lyapunov_uncertainty(self) -> float | None:
        """A bound on the exponent's error (about 95 %), per unit tau."""
        return None if self.lyapunov is None else self.lyapunov.get("uncertainty")

    # -- storage --------------------------------------------------------------------------
    def to_dict(self) -> dict:
        out = {"values": self.values, "start": self.start, "status": self.status}
        if self.status == "failed":
            out["error"] = self.error
        out["x0"] = None if self.x0 is None else np.asarray(self.x0).tolist()
        out["classification"] = {c: k.describe() for c, k in self.classification.items()}
        out["extremes"] = {s: e.to_dict() for s, e in self.extremes.items()}
        out["meshing_states"] = self.meshing_states
        if self.meshing_regime:
            out["meshing_regime"] = self.meshing_regime
        out["lyapunov"] = self.lyapunov
        out["spectra"] = self.spectra
        out["poincare"] = {s: np.asarray(v).tolist() for s, v in self.poincare.items()}
        if self.spread:
            out["poincare_spread"] = self.spread
        out["x_final"] = None if self.x_final is None else np.asarray(self.x_final).tolist()
        out["integration"] = self.integration
        if self.attempts is not None:
            out["attempts"] = self.attempts
        if self.verdict is not None:
            out["verdict"] = self.verdict
        return out

    @classmethod
    def from_dict(cls, d: dict) -> RunRecord:
        return cls(
            values={k: float(v) for k, v in d["values"].items()},
            status=d["status"],
            classification={
                c: Classification(k["motion"], k["period"], k["evidence"])
                for c, k in d["classification"].items()
            },
            extremes={s: Extremes(e["max"], e["min"]) for s, e in d["extremes"].items()},
            start=d.get("start", "default"),
            x0=None if d.get("x0") is None else _floats(d["x0"]),
            meshing_states=d.get("meshing_states", {}),
            meshing_regime=d.get("meshing_regime", {}),
            lyapunov=d.get("lyapunov"),
            spectra=d.get("spectra", {}),
            poincare={s: _floats(v) for s, v in d["poincare"].items()},
            spread=d.get("poincare_spread", {}),
            x_final=None if d.get("x_final") is None else _floats(d["x_final"]),
            integration=d.get("integration", {}),
            error=d.get("error"),
            attempts=d.get("attempts"),
            verdict=d.get("verdict"),
        )
