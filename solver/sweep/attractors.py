"""From map runs to attractors: each run judged, runs of one grid point grouped.

A run (one initial state at one grid point) gets the attractor's verdict
(``analysis.settle``: continued from where it ended until settled), and its meshing regime
is read from the extremes of each mesh coordinate against the zeros of the model's own
force (``analysis.meshing``, after Kahraman and Singh 1990, "Non-linear dynamics of a spur
gear pair", J. Sound Vib. 142): no impact, single-sided or double-sided impact, no contact
for the dead zone; for a force law loaded inside the gap (the study's polynomial) the
regimes say where the force changes sign instead.

Runs of one grid point reach the same attractor when they end with the same status and

* periodic with the same period per coordinate: their last n Poincare points coincide as
  sets (up to a cyclic shift), within ``SAME_TOL`` times the size of the orbit;
* both not periodic: their extremes over the window agree within ``CLOUD_TOL`` of the
  attractor's size (a chaotic or quasi-periodic set sampled over 100 periods fills its
  bounding box to within a few per cent; two distinct ones rarely share it).  Their
  verdicts (quasi-periodic, chaotic, undetermined) may differ: they rest on finite samples
  of the same set.  The attractor takes the majority's verdicts and, when its runs
  disagree, reports the count of each (``verdicts``).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..analysis.classify import Classification
from ..analysis.lyapunov import LyapunovEstimate
from ..analysis.meshing import contract_regimes, meshing_regime
from ..analysis.record import Extremes, RunRecord
from ..analysis.settle import BUDGET, FIRST_WINDOW, per_coordinate, settle

__all__ = ["Attractor", "group_runs", "meshing_regime", "outcome"]  # meshing_regime: re-exported

SAME_TOL = 1e-4  # periodic orbits: Poincare sets closer than this (relative) are one
CLOUD_TOL = 0.05  # non-periodic sets: extremes closer than this (relative) are one


def outcome(
    system,
    start: str,
    status: str,
    poincare,
    xmin,
    xmax,
    running,
    *,
    tol,
    rtol,
    atol,
    values: dict | None = None,
    x0=None,
    engine: str,
    t_end: float = 0.0,
    method: str = "dop853",
    budget: int = BUDGET,
    first_window: int = FIRST_WINDOW,
) -> RunRecord:
    """The record of one run of a map: ``poincare`` (K + 1, n) its Poincare points and
    end state, ``xmin``/``xmax`` (n,) its extremes, ``running`` its running exponent over
    the last periods (or None); ``values`` the grid point's named values, ``x0`` (n,)
    where it started, ``t_end`` where it ended (tau); ``engine`` names what integrated it.
    The run is judged and continued as ``analysis.settle`` says (``budget`` periods in
    all).  The record keeps the last 64 Poincare points, the spread per coordinate, and
    the verdict's summary (``Verdict.summary``)."""
    c = system.contract
    if status != "ok":
        motion = "divergent" if status == "divergent" else "undetermined"
        return RunRecord(
            values=dict(values or {}),
            status=status,
            classification={k: Classification(motion, None, {}) for k in system.coordinates},
            extremes={
                s: Extremes(float(xmax[k]), float(xmin[k])) for k, s in enumerate(system.states)
            },
            start=start,
            x0=None if x0 is None else np.array(x0, dtype=float),
            meshing_regime=dict.fromkeys(c.force_sign, "undetermined"),
            poincare={s: np.asarray(poincare[-64:, k], float) for k, s in enumerate(system.states)},
            verdict={"motion": motion, "period": None, "periods_run": None},
        )
    lyap = None
    if running is not None and np.all(np.isfinite(running)):
        lyap = LyapunovEstimate.from_running(running, rtol, atol, engine, system.period)
    K = poincare.shape[0] - 1
    st = settle(
        system,
        np.asarray(poincare[:-1], float).T,
        poincare[-1],
        t_end,
        periods_run=int(round(t_end / system.period)),
        tol=tol * max(float(np.ptp(poincare, axis=0).max()), 1.0),
        method=method,
        rtol=rtol,
        atol=atol,
        budget=budget,
        first_window=first_window,
        exponent=running is not None,
        lyapunov=lyap if lyap is not None and len(running) >= K else None,
    )
    v = st.verdict
    if st.extremes is not None:
        xmin, xmax = st.extremes
    spreads = v.evidence.get("spread", {})
    verdicts = per_coordinate(system, v)
    meshing = contract_regimes(c, xmin, xmax)
    tail = np.asarray(st.points[:, -64:], float)
    summary = st.lyapunov
    if summary is not None:
        summary = {"exponent": summary["exponent"], "uncertainty": summary["uncertainty"]}
    return RunRecord(
        values=dict(values or {}),
        status=status,
        classification=verdicts,
        extremes={s: Extremes(float(xmax[k]), float(xmin[k])) for k, s in enumerate(system.states)},
        start=start,
        x0=None if x0 is None else np.array(x0, dtype=float),
        meshing_regime=meshing,
        lyapunov=summary,
        poincare={s: tail[k].copy() for k, s in enumerate(system.states)},
        spread={k: e["displacement"] for k, e in spreads.items()},
        x_final=st.x_final.copy(),
        verdict=v.summary(),
    )


@dataclass(frozen=True)
class Attractor:
    """An attractor (or a failure outcome: divergent, left the valid range) at one grid
    point, with the share of initial states that reached it and which ones."""

    share: float
    starts: tuple[str, ...]
    run: RunRecord  # the representative: the first run with the majority's verdicts
    votes: dict = field(default_factory=dict)  # per coordinate, when the runs disagree

    def to_dict(self, states) -> dict:
        r = self.run
        why = {c: k.evidence["why"] for c, k in r.classification.items() if "why" in k.evidence}
        return {
            "share": self.share,
            "starts": list(self.starts),
            "status": r.status,
            "motion": {c: k.motion for c, k in r.classification.items()},
            "period": {c: k.period for c, k in r.classification.items()},
            "lyapunov": r.lyapunov_exponent,
            "lyapunov_uncertainty": r.lyapunov_uncertainty,
            "max": {s: r.max(s) for s in states},
            "min": {s: r.min(s) for s in states},
            "meshing": dict(r.meshing_regime),
            "poincare_spread": dict(r.spread),
            "state": [float(v) for v in r.tail[-1]],
            "periods_run": (r.verdict or {}).get("periods_run"),
            "verdict": r.verdict,
            **({"why": why} if why else {}),
            **({"verdicts": self.votes} if self.votes else {}),
        }


def _cycle(run: RunRecord) -> int | None:
    """The common period of all coordinates (their least common multiple), or None."""
    periods = [k.period for k in run.classification.values()]
    if run.status != "ok" or not periods or any(p is None for p in periods):
        return None
    return int(np.lcm.reduce(periods))


def _kind(run: RunRecord) -> tuple:
    """What two runs must share before their geometry is compared: the failure status,
    or periodic with the same period per coordinate, or not periodic (quasi-periodic,
    chaotic and undetermined verdicts of one set differ only in finite-sample evidence)."""
    if run.status != "ok":
        return (run.status,)
    if _cycle(run) is None:
        return ("not periodic",)
    return ("periodic", tuple(sorted((c, k.period) for c, k in run.classification.items())))


def same_attractor(a: RunRecord, b: RunRecord) -> bool:
    if _kind(a) != _kind(b):
        return False
    if a.status != "ok":
        return True  # one failure outcome per kind
    n = _cycle(a)
    if n is not None and n <= min(len(a.tail), len(b.tail)):
        A, B = a.tail[-n:], b.tail[-n:]
        size = max(float(np.ptp(np.vstack([A, B]), axis=0).max()), 1.0)
        gaps = [np.abs(A - np.roll(B, s, axis=0)).max() for s in range(n)]
        return min(gaps) <= SAME_TOL * size
    size = max(float(np.max(a.xmax - a.xmin)), float(np.max(b.xmax - b.xmin)), 1e-12)
    gap = max(np.abs(a.xmax - b.xmax).max(), np.abs(a.xmin - b.xmin).max())
    return gap <= CLOUD_TOL * size


def _attractor(members: list[RunRecord], total: int) -> Attractor:
    """The majority's verdicts (ties: the earlier start) and, if the runs disagree, the
    count of each verdict per coordinate."""
    verdicts = [tuple(sorted((c, k.motion) for c, k in r.classification.items())) for r in members]
    best = max(verdicts, key=lambda v: (verdicts.count(v), -verdicts.index(v)))
    run = members[verdicts.index(best)]
    votes = {}
    for coord in run.classification:
        seen = [r.motion(coord) for r in members]
        if len(set(seen)) > 1:
            votes[coord] = {m: seen.count(m) for m in dict.fromkeys(seen)}
    return Attractor(len(members) / total, tuple(r.start for r in members), run, votes)


def group_runs(runs: list[RunRecord]) -> list[Attractor]:
    """Group the runs of one grid point into attractors, largest share first (ties: the
    order of the starts, so the forward start's attractor comes first)."""
    groups: list[list[RunRecord]] = []
    for r in runs:
        for g in groups:
            if same_attractor(g[0], r):
                g.append(r)
                break
        else:
            groups.append([r])
    total = max(len(runs), 1)
    order = sorted(range(len(groups)), key=lambda k: -len(groups[k]))
    return [_attractor(groups[k], total) for k in order]
