"""The one record of a continued branch and the one record of a located bifurcation, for
every continuation problem (shooting on the stroboscopic map, harmonic balance on the
Fourier coefficients); ``engine.py`` makes them.

A branch point keeps the parameter value, the orbit's state at tau = 0 (mod nT), its
Floquet multipliers with the verdict (``floquet.py``: stable, neutral or unstable) and
the sign of the tangent's parameter component (+1 or -1: the side a fold turns to); a
harmonic-balance point also keeps its Fourier coefficients, and its branch the
discretisation that reads them (mean, half peak-to-peak, RMS, the top harmonics' share).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field, replace

import numpy as np

__all__ = ["Bifurcation", "Branch", "BranchPoint"]


def _complex(z) -> dict | None:
    return None if z is None else {"re": float(z.real), "im": float(z.imag)}


# A bifurcation located to the continuation's tolerance has its critical multiplier
# within about the square root of that distance of +1 or -1 when smooth (1e-4 on the
# shipped models' folds); one farther than this from it is no smooth one
NON_SMOOTH = 0.05
# the multiplier each kind of bifurcation crosses the unit circle at (a Neimark-Sacker
# pair anywhere on it)
CRITICAL = {"fold": 1.0, "branch point": 1.0, "period-doubling": -1.0}


@dataclass(frozen=True)
class Bifurcation:
    """A bifurcation located on a branch.

    Attributes
    ----------
    kind : str
        ``"fold"`` (a multiplier through +1: the branch turns, or a branch point, which
        :meth:`Branch.named` tells apart),
        ``"period-doubling"`` (through -1) or ``"neimark-sacker"`` (a complex pair).
    value : float
        The parameter there (non-dimensional, as the model's parameter).
    x0 : ndarray, (n_states,)
        The orbit's state at tau = 0 (mod nT) there.
    multiplier : complex or None
        The critical Floquet multiplier there (None: the branch ran without stability).
    parameter : str
        The parameter's name.
    index : int
        The index of the first branch point past it.
    evidence : Mapping[str, float or str]
        What else shows it (harmonic balance: ``hill_vs_monodromy``, the largest distance
        of Hill's multipliers from a time integration's monodromy, and
        ``max_monodromy_multiplier``; ``location``: why it was not located, the corrector
        having failed inside the step).
    """

    kind: str
    value: float
    x0: np.ndarray
    multiplier: complex | None = None
    parameter: str = ""
    index: int = -1
    evidence: Mapping = field(default_factory=dict)
    turns: bool | None = None  # a "fold": whether the branch turns there (None: not known)

    @property
    def name(self) -> str:
        """The kind in words: a ``"fold"`` where the branch does not turn is a branch
        point, a multiplier through +1 without a turn (a symmetry-breaking pitchfork, for
        one).  Where the located multiplier is not at the kind's critical value (+1, -1)
        the name says "non-smooth": the branch turns, or its test changes sign, where an
        orbit grazes a contact edge and its multipliers jump there instead of passing the
        critical value (di Bernardo et al. 2008, "Piecewise-smooth Dynamical Systems"), so
        the smooth bifurcation's evidence is missing and it is not called one.  A point
        whose location failed (``evidence["location"]``) is not judged so: its multiplier
        was read a step away."""
        kind = self.kind
        if kind == "fold" and self.turns is False:
            kind = "branch point"
        target = CRITICAL.get(kind)
        located = "location" not in self.evidence
        if target is not None and self.multiplier is not None and located:
            if abs(self.multiplier - target) > NON_SMOOTH:
                return f"non-smooth {kind}"
        return kind

    @property
    def jump(self) -> bool:
        """Whether a slow sweep jumps here: the branch turns (a fold, smooth or not)."""
        return self.kind == "fold" and self.turns is not False

    def to_dict(self) -> dict:
        """Kind, parameter name and value (also under the parameter's own name), index,
        multiplier (re, im), x0 and the evidence."""
        out = {
            "kind": self.kind,
            "name": self.name,
            "parameter": self.parameter,
            "value": float(self.value),
        }
        if self.parameter and self.parameter not in ("kind", "name", "index", "multiplier", "x0"):
            out[self.parameter] = float(self.value)
        out |= {
            "index": int(self.index),
            "multiplier": _complex(self.multiplier),
            "x0": [float(v) for v in self.x0],
        }
        return out | {k: v if isinstance(v, str) else float(v) for k, v in self.evidence.items()}

    describe = to_dict


@dataclass(frozen=True)
class BranchPoint:
    """One solution on a branch: ``value`` of the parameter, ``x0`` (n_states,) the state
    at tau = 0 (mod nT), ``multipliers`` (by decreasing modulus; None without stability),
    ``stable`` and ``stability`` (``floquet.py``), ``tangent_sign`` (sign of
    d(parameter)/d(arclength)), ``coefficients`` (harmonic balance: states x (2H + 1),
    c0, c1, s1, ...; None for shooting)."""

    value: float
    x0: np.ndarray
    multipliers: np.ndarray | None
    stable: bool | None
    stability: str | None
    tangent_sign: int
    coefficients: np.ndarray | None = None


@dataclass(frozen=True)
class Branch:
    """A continued branch of period-n orbits in the order of arclength, the bifurcations
    located on it and how it ended.

    ``status``: "complete" (reached the end asked for), "boundary" (stopped at the edge
    of the parameter's valid range), "turned" (a fold took it out at the start's side),
    "stalled" (the step fell below its minimum), "max-points"; ``message`` says it in
    words, ``notes`` what a user may do about it.  ``harmonic_balance``: the
    discretisation of a harmonic-balance branch (None for shooting), which the Fourier
    statistics (:meth:`series`, :meth:`mean`, ...) need.
    """

    parameter: str
    n: int
    points: tuple[BranchPoint, ...] = ()
    bifurcations: tuple[Bifurcation, ...] = ()
    status: str = "complete"
    message: str = ""
    notes: tuple[str, ...] = ()
    wall_time: float = 0.0
    state_names: tuple = ()
    model: dict = field(default_factory=dict)  # name, hash, base values and scales
    harmonic_balance: object = None

    @property
    def values(self) -> np.ndarray:
        return np.array([p.value for p in self.points], dtype=float)

    @property
    def states(self) -> tuple[np.ndarray, ...]:
        return tuple(p.x0 for p in self.points)

    @property
    def stable(self) -> np.ndarray:
        return np.array([bool(p.stable) for p in self.points], dtype=bool)

    @property
    def multipliers(self) -> list:
        return [p.multipliers for p in self.points if p.multipliers is not None]

    def __repr__(self) -> str:
        v = self.values
        span = f"{v.min():.4g} to {v.max():.4g}" if v.size else "no points"
        kinds = ", ".join(sorted({self.named(b) for b in self.bifurcations}))
        return (
            f"Branch({self.model.get('model', '?')}: period-{self.n} in {self.parameter} "
            f"{span}, {v.size} points, {int(np.sum(self.stable))} stable, "
            f"{len(self.bifurcations)} bifurcation(s){' (' + kinds + ')' if kinds else ''}; "
            f"{self.status})"
        )

    def named(self, b: Bifurcation) -> str:
        """``b``'s kind in words: a ``"fold"`` where the branch does not turn (the
        tangent's parameter component keeps its sign across it) is a branch point, a
        multiplier through +1 without a turn (a symmetry-breaking pitchfork, for one)."""
        if b.turns is not None or b.kind != "fold" or not 1 <= b.index < len(self.points):
            return b.name
        before, after = self.points[b.index - 1], self.points[b.index]
        return replace(b, turns=before.tangent_sign != after.tangent_sign).name

    def summary(self) -> str:
        """A few lines: the branch, its stability, each bifurcation, how it ended."""
        lines = [repr(self)[len("Branch(") : -1]]
        for b in self.bifurcations[:6]:
            lines.append(
                f"  {self.named(b)} at {self.parameter} = {b.value:.8g}, multiplier "
                f"{b.multiplier.real:+.6f}{b.multiplier.imag:+.6f}i"
            )
        if len(self.bifurcations) > 6:
            lines.append(f"  ... {len(self.bifurcations) - 6} more bifurcations")
        lines.append(self.message or f"status: {self.status}")
        return "\n".join(lines)

    def describe(self) -> dict:
        """The branch under the API's names: ``n``, ``values``, ``states`` (one row per
        point, in the order of ``state_names``), ``stable``, ``stability`` and
        ``multipliers`` (per point ``{"re": [...], "im": [...]}``, or None without
        stability), the bifurcations, ``status`` and ``message``."""

        def complexes(m):
            return None if m is None else {"re": np.real(m).tolist(), "im": np.imag(m).tolist()}

        return {
            "parameter": self.parameter,
            "n": self.n,
            "values": [float(p.value) for p in self.points],
            "states": [[float(v) for v in p.x0] for p in self.points],
            "stable": [bool(p.stable) for p in self.points],
            "stability": [p.stability for p in self.points],
            "multipliers": [complexes(p.multipliers) for p in self.points],
            "bifurcations": [b.to_dict() for b in self.bifurcations],
            "status": self.status,
            "message": self.message,
        }

    def to_dict(self) -> dict:
        """:meth:`describe` after the header block (``provenance.header``: version, model,
        hash, scales back to SI, the values it was run with) and the state names."""
        from ..provenance import header

        m = self.model
        head = {}
        if m:
            head = header(m["model"], m["model_hash"], m["scales"], m["base_values"])
        return head | {"state_names": list(self.state_names)} | self.describe()

    def to_table(self) -> tuple[list, list]:
        """One row per branch point: the parameter, stability, largest |multiplier|, x0."""
        n = len(self.points[0].x0) if self.points else 0
        names = self.state_names or tuple(f"x0_{i}" for i in range(n))
        columns = [self.parameter, "stable", "max_multiplier", *names]
        rows = [
            [
                float(p.value),
                bool(p.stable),
                float("nan") if p.multipliers is None else float(np.max(np.abs(p.multipliers))),
                *map(float, p.x0),
            ]
            for p in self.points
        ]
        return columns, rows

    def save(self, path, **extra):
        """Write to ``path``: ``.json``, ``.csv`` or ``.mat`` (see ``solver/export.py``)."""
        from ..export import save

        return save(self, path, **extra)

    # -- the Fourier statistics of a harmonic-balance branch ------------------------------
    def _fourier(self):
        if self.harmonic_balance is None:
            raise ValueError(
                "this branch was continued by shooting and carries no Fourier coefficients; "
                "continue it with continue_hb for the harmonic-balance statistics"
            )
        return self.harmonic_balance

    def _coefficients(self, i: int, harmonics=slice(None)) -> np.ndarray:
        return np.array([p.coefficients[i, harmonics] for p in self.points])

    def series(self, name: str, points: int = 512) -> np.ndarray:
        """``name`` over one period at every point, (len(points), points)."""
        prob = self._fourier()
        s = 2 * np.pi * np.arange(points) / points
        return prob.time_series(self._coefficients(prob.system.index(name)), s)

    def mean(self, name: str) -> np.ndarray:
        """The mean of ``name`` (its coefficient c0) at every point."""
        return self._coefficients(self._fourier().system.index(name), 0)

    def extrema(self, name: str) -> tuple[np.ndarray, np.ndarray]:
        """Min and max of ``name`` at every point, read off the trigonometric polynomial
        at its refined extrema (``aft.HarmonicBalance.extrema``), not off samples."""
        prob = self._fourier()
        return prob.extrema(self._coefficients(prob.system.index(name)))

    def amplitude(self, name: str) -> np.ndarray:
        """Half peak-to-peak of ``name`` at every point (refined extrema)."""
        lo, hi = self.extrema(name)
        return (hi - lo) / 2

    def maximum(self, name: str) -> np.ndarray:
        return self.extrema(name)[1]

    def minimum(self, name: str) -> np.ndarray:
        return self.extrema(name)[0]

    def rms(self, name: str) -> np.ndarray:
        """``sqrt(c0^2 + (1/2) sum_k (c_k^2 + s_k^2))`` of ``name`` at every point."""
        C = self._coefficients(self._fourier().system.index(name))
        return np.sqrt(C[:, 0] ** 2 + 0.5 * np.sum(C[:, 1:] ** 2, axis=1))

    def tail_shares(self, top: int | None = None) -> np.ndarray:
        """Per point, the largest share (RMS sense, over the coordinates) of the response
        that the highest ``top`` harmonics carry (default a quarter of H)."""
        prob = self._fourier()
        top = top or max(1, prob.H // 4)
        out = np.zeros(len(self.points))
        for c in prob.system.coordinates:
            C = self._coefficients(prob.system.index(c), slice(1, None))
            a2 = C[:, 0::2] ** 2 + C[:, 1::2] ** 2
            total = a2.sum(axis=1)
            tail = a2[:, -top:].sum(axis=1)
            share = np.sqrt(np.divide(tail, total, out=np.zeros_like(total), where=total > 0))
            out = np.maximum(out, share)
        return out

    def records(self) -> list[dict]:
        """One record per point: the parameter under its own name, ``stable``,
        ``stability`` and per coordinate its ``mean``, ``amplitude`` (half peak-to-peak),
        ``rms``, ``min`` and ``max`` (harmonic balance; extremes refined on the
        trigonometric polynomial)."""
        coords = self._fourier().system.coordinates
        stats = {c: (self.mean(c), *self.extrema(c), self.rms(c)) for c in coords}
        out = []
        for k, p in enumerate(self.points):
            rec = {self.parameter: p.value, "stable": p.stable, "stability": p.stability}
            for c in coords:
                m, lo, hi, r = stats[c]
                rec[c] = {
                    "mean": float(m[k]),
                    "amplitude": float(hi[k] - lo[k]) / 2,
                    "rms": float(r[k]),
                    "min": float(lo[k]),
                    "max": float(hi[k]),
                }
            out.append(rec)
        return out
