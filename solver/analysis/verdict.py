"""One verdict per attractor, each label on positive evidence.

A run is judged window by window (``settle.py`` runs the windows, each continuing from
where the last one ended).  A window holds the Poincare points of the **whole state**
(one per forcing period T) and, when it was run with the tangent vector, the largest
exponent ``lambda`` with its uncertainty ``U`` (``lyapunov.uncertainty``: bias, bounded
oscillation and batch means over eight blocks).  The labels and their evidence:

* **period-n** -- the shooting check (``orbit_check.py``) from the run's last point
  converges to an orbit of minimal period n whose multipliers all lie inside the unit
  circle, and the run is on it: its Poincare points repeat after n periods within the
  stated tolerance, or they are converging to it (the gaps ``|P_{k+n} - P_k|`` shrink
  over the window).  The exponent is then the orbit's ``log max|mu| / (n T)``.
* **chaotic** -- in the last two windows the exponent's interval ``lambda +- U`` lies
  above zero, and an independent second test agrees: the 0-1 test for chaos
  (``zero_one.py``; Gottwald and Melbourne 2004, 2009) on the most spread coordinate gives
  ``K >= K_CHAOS``, or, where it does not (weak chaos: K converges slowly in the number
  of samples), the exponent of two nearby trajectories (``two_trajectory.py``, no
  Jacobian) has its interval above zero too.  Chaos in an earlier window
  that ends on a periodic orbit is reported as a chaotic transient, with its length.
* **quasi-periodic** -- in the last two windows the exponent's interval lies within
  ``+-delta`` of zero (``delta = DELTA / T``: a growth of at most ``e^0.01`` per period),
  the 0-1 test reads regular (``K <= K_REGULAR``), the Poincare section is a closed curve
  (correlation dimension in ``classify.CURVE``) and its spectrum is explained by one
  incommensurate rotation number (``torus.py``: two base frequencies ``1/T`` and ``rho/T``).

Anything else is ``undetermined`` with the reason of the last window.  The verdict
belongs to the attractor; each mesh coordinate gets its spread (the extent of its
Poincare cloud, and its share of the largest one: a coordinate slaved to a chaotic one
through a weak coupling keeps the attractor's verdict but a small share).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .classify import CURVE, MAX_PERIOD, correlation_dimension
from .lyapunov import LyapunovEstimate

__all__ = ["DELTA", "K_CHAOS", "K_REGULAR", "Verdict", "Window", "candidates", "judge"]

DELTA = 0.01  # |lambda| T below this reads as zero: a growth of at most e^0.01 per period
K_CHAOS, K_REGULAR = 0.8, 0.2  # the 0-1 test's readings (see zero_one.py)
NEAR = 0.05  # a converging candidate's last gap, relative to the cloud (see candidates)


@dataclass(frozen=True)
class Window:
    """Periods ``start`` to ``start + K`` of a run: Poincare points (n, K) and the
    exponent over the same periods (None: run without the tangent vector)."""

    start: int
    points: np.ndarray
    lyapunov: LyapunovEstimate | None = None

    @property
    def end(self) -> int:
        return self.start + self.points.shape[1]


@dataclass(frozen=True)
class Verdict:
    """The attractor's motion, its period multiple, the periods the run took, and the
    evidence (``why`` when undetermined)."""

    motion: str  # "period-n", "quasi-periodic", "chaotic", "divergent", "undetermined"
    period: int | None
    periods_run: int
    evidence: dict = field(default_factory=dict)

    def describe(self) -> dict:
        return {
            "motion": self.motion,
            "period": self.period,
            "periods_run": self.periods_run,
            "evidence": self.evidence,
        }

    def summary(self) -> dict:
        """The verdict with the key of its evidence only (what a map run keeps): the
        orbit's largest multiplier, or the last window's exponent interval, 0-1 test and
        rotation number; the reason of an undetermined verdict; a chaotic transient."""
        ev = self.evidence
        out = {"motion": self.motion, "period": self.period, "periods_run": self.periods_run}
        if "orbit" in ev:
            out["largest_multiplier"] = ev["orbit"]["largest_multiplier"]
            out["converging"] = ev.get("converging")
        windows = ev.get("windows") or []
        if windows and "orbit" not in ev:
            last = windows[-1]
            if "exponent" in last:
                out["exponent_interval"] = last["exponent"]["interval"]
            if "zero_one" in last:
                out["zero_one_K"] = last["zero_one"]["K"]
            if "rotation_number" in last:
                out["rotation_number"] = last["rotation_number"]
            if "second_test" in last:
                out["second_test"] = last["second_test"]
            if "interval" in last.get("two_trajectory", {}):
                out["two_trajectory_interval"] = last["two_trajectory"]["interval"]
        for key in ("why", "transient_chaos"):
            if key in ev:
                out[key] = ev[key]
        return out


def candidates(points: np.ndarray, tol: float) -> tuple[int | None, list[int]]:
    """Period multiples to check: the smallest n <= 32 whose points repeat within ``tol``
    (absolute), and up to two n whose last gaps are below ``NEAR`` of the cloud and
    shrinking (a run still converging to a period-n orbit)."""
    K = points.shape[1]
    scale = max(float(np.ptp(points, axis=1).max()), 1.0)
    strict, near = None, []
    for n in range(1, min(MAX_PERIOD, K // 2) + 1):
        gaps = np.max(np.abs(points[:, n:] - points[:, :-n]), axis=0)
        if strict is None and gaps.max() <= tol:
            strict = n
            break
        q = max(n, gaps.size // 4)
        last, first = gaps[-q:].max(), gaps[:q].max()
        if len(near) < 2 and last <= NEAR * scale and last < 0.9 * first:
            near.append(n)
    return strict, [n for n in near if strict is None or n < strict]


def spread(system, points: np.ndarray) -> dict:
    """Per mesh coordinate: the extent (max - min) of its Poincare displacement and
    velocity, and its share of the largest displacement extent."""
    ext = {}
    for c in system.coordinates:
        i, j = system.index(c), system.velocity_index(c)
        ext[c] = {
            "displacement": float(np.ptp(points[i])),
            "velocity": float(np.ptp(points[j])),
        }
    top = max((e["displacement"] for e in ext.values()), default=0.0)
    for e in ext.values():
        e["share"] = e["displacement"] / top if top > 0 else None
    return ext


def _exponent(lyap: LyapunovEstimate, period: float) -> dict:
    lam, U = lyap.exponent, lyap.uncertainty
    delta = DELTA / period
    if lam - U > 0:
        sign = "positive"
    elif lam + U < 0 and lam + U < -delta:
        sign = "negative"
    elif abs(lam) + U <= delta:
        sign = "zero"
    else:
        sign = "unresolved"
    return {
        "exponent": lam,
        "uncertainty": U,
        "interval": [lam - U, lam + U],
        "delta": delta,
        "sign": sign,
        "periods": lyap.periods,
    }


def _pair(system, w: Window, upper: float) -> dict:
    """The two-trajectory exponent over the window (``two_trajectory.py``), or why not."""
    from .two_trajectory import two_trajectory

    try:
        return two_trajectory(
            system, w.points[:, 0], w.points.shape[1], t0=w.start * system.period, upper=upper
        )
    except FloatingPointError as err:
        return {"failed": str(err)}


def judge(system, w: Window, tol: float) -> dict:
    """The evidence of one non-periodic window and what it reads as: ``label`` one of
    ``chaotic``, ``torus`` or ``unsettled`` (with ``why``)."""
    from .torus import torus_evidence
    from .zero_one import zero_one

    ev: dict = {"window": [w.start, w.end]}
    if w.lyapunov is None:
        return ev | {"label": "unsettled", "why": "no exponent over this window"}
    ex = ev["exponent"] = _exponent(w.lyapunov, system.period)
    ext = spread(system, w.points)
    widest = max(ext, key=lambda c: ext[c]["displacement"])
    series = w.points[system.index(widest)]
    if ex["sign"] in ("positive", "zero") and np.ptp(series) > 0 and series.size >= 100:
        z = zero_one(series)
        ev["zero_one"] = {"K": z.K, "coordinate": widest, "samples": z.samples}
    K = ev.get("zero_one", {}).get("K")
    if ex["sign"] == "positive":
        if K is not None and K >= K_CHAOS:
            return ev | {"label": "chaotic", "second_test": "0-1 test"}
        pair = _pair(system, w, ex["interval"][1])
        ev["two_trajectory"] = pair
        if "interval" in pair and pair["interval"][0] > 0:
            return ev | {"label": "chaotic", "second_test": "two-trajectory exponent"}
        why = (
            "the exponent is positive but the 0-1 test "
            + ("could not run" if K is None else f"reads K = {K:.2f} (chaos needs >= {K_CHAOS})")
            + " and the two-trajectory exponent "
            + (
                f"lies in [{pair['interval'][0]:.2e}, {pair['interval'][1]:.2e}]"
                if "interval" in pair
                else f"failed: {pair['failed']}"
            )
        )
        return ev | {"label": "unsettled", "why": why}
    if ex["sign"] == "zero":
        dim = correlation_dimension(w.points[[system.index(widest), system.velocity_index(widest)]])
        # rows that carry only integration noise would dilute the explained share
        rows = [system.index(c) for c in system.coordinates if (ext[c]["share"] or 0) >= 1e-2]
        torus = torus_evidence(w.points[rows])
        ev["correlation_dimension"] = dim
        ev["torus"] = torus.describe()
        curve = dim is not None and CURVE[0] <= dim <= CURVE[1]
        if K is not None and K <= K_REGULAR and curve and torus.is_torus:
            return ev | {"label": "torus", "rotation_number": torus.rotation_number}
        parts = []
        if K is None or K > K_REGULAR:
            parts.append("0-1 test " + ("not run" if K is None else f"K = {K:.2f}"))
        if not curve:
            parts.append(
                "section not a curve (dimension "
                + ("unknown" if dim is None else f"{dim:.2f}")
                + f", a curve is {CURVE[0]} to {CURVE[1]})"
            )
        if not torus.is_torus:
            parts.append("spectrum not one incommensurate rotation number")
        return ev | {"label": "unsettled", "why": "exponent near zero, but " + "; ".join(parts)}
    if ex["sign"] == "negative":
        why = (
            "the exponent is negative, yet no attracting orbit of period <= "
            f"{MAX_PERIOD} was found (not settled, or a longer period)"
        )
        return ev | {"label": "unsettled", "why": why}
    lo, hi = ex["interval"]
    why = (
        f"the exponent's interval [{lo:.2e}, {hi:.2e}] holds zero and is wider than "
        f"+-{ex['delta']:.1e}"
    )
    return ev | {"label": "unsettled", "why": why}


def settled(judged: list[dict]) -> str | None:
    """The label the last two judged windows agree on (``chaotic`` or ``torus``)."""
    if len(judged) >= 2 and judged[-1]["label"] == judged[-2]["label"] != "unsettled":
        return judged[-1]["label"]
    return None
