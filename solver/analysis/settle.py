"""Run on until the verdict is settled or the budget is spent.

``settle`` takes a run where it stands -- its Poincare points so far, its end state and
time -- and judges it (``verdict.py``).  A period-n verdict needs no more than the
shooting check; anything else is continued **from the run's end state** in windows of
``first_window``, then twice, four times ... as many periods, each run with the tangent
vector (the exponent over the window) and judged on its own, until the last two windows
agree (chaotic, or a torus) or ``budget`` periods (counted from the run's start) are spent.
The verdict records the periods it took and every window's evidence; a periodic verdict
after chaotic windows records the chaotic transient and bounds its length.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from ..integrate import get_method, simulate
from ..integrate.run import integrate
from ..integrate.spec import RunSpec
from ..system import System
from .classify import Classification
from .lyapunov import LyapunovEstimate, largest_lyapunov
from .orbit_check import OrbitCheck, check_orbit
from .verdict import Verdict, Window, candidates, judge, settled, spread

__all__ = ["BUDGET", "FIRST_WINDOW", "Settled", "per_coordinate", "settle", "settle_many"]

BUDGET = 3000  # periods a verdict may take, counted from the run's start
FIRST_WINDOW = 400  # the first continued window; each next one is twice as long
KEEP = 1000  # Poincare points of the last window a record keeps


@dataclass(frozen=True)
class Settled:
    """The verdict, the last window's Poincare points (n, K <= KEEP), where the run ended,
    the exponent's summary (a dict, or None), the orbit of a periodic verdict, and the
    last window's exponent estimate with its running history (or None), and the state
    extremes ``(xmin, xmax)`` over the last continued window (None: not continued)."""

    verdict: Verdict
    points: np.ndarray
    x_final: np.ndarray
    t_final: float
    lyapunov: dict | None
    orbit: OrbitCheck | None
    estimate: LyapunovEstimate | None = None
    extremes: tuple | None = None


def _periodic(system: System, w: Window, x_end, t_end, tol: float) -> OrbitCheck | None:
    """The attracting orbit the window's run is on or converging to, or None."""
    strict, near = candidates(w.points, tol)
    tried = set()
    for n in [m for m in (strict, *near) if m is not None]:
        check = check_orbit(system, x_end, n, t0=t_end)
        tried.add(n)
        m = check.minimal_period
        if check.converged and m is not None and m < n and m not in tried:
            check = check_orbit(system, check.x, m, t0=t_end)
            tried.add(m)
        # a neutral orbit (one of a family) only where the run's points already repeat
        # on it: the run is on the family and stays there
        if check.attracting or (check.neutral and n == strict and check.n == n):
            return check
    return None


def _extend(system, x, t, periods: int, run: dict, exponent: bool):
    """``periods`` more periods from state ``x`` at time ``t``: Poincare points (n, L),
    end state, status, the exponent over them (or None), extremes (xmin, xmax)."""
    if get_method(run["method"]).family == "native":
        res = integrate(system, x, _window_spec(periods, run, exponent, t))
        return _window(res, 0, system, periods, run, exponent)
    tr = simulate(
        system,
        x,
        method=run["method"],
        rtol=run["rtol"],
        atol=run["atol"],
        t0=t,
        transient=0,
        periods=periods,
        samples_per_period=1,
        steps_per_period=run["steps_per_period"],
    )
    lyap = None
    if exponent and tr.status == "ok":
        try:
            lyap = largest_lyapunov(system, x, t0=t, periods=periods, rtol=run["rtol"])
        except (FloatingPointError, RuntimeError):
            lyap = None
    return tr.poincare, tr.x_final.copy(), tr.status, lyap, (tr.x.min(axis=1), tr.x.max(axis=1))


def settle(
    system: System,
    points: np.ndarray,
    x_end,
    t_end: float,
    *,
    periods_run: int,
    tol: float,
    method: str = "dop853",
    rtol: float = 1e-8,
    atol: float = 1e-10,
    steps_per_period: int = 512,
    budget: int = BUDGET,
    first_window: int = FIRST_WINDOW,
    exponent: bool = True,
    lyapunov: LyapunovEstimate | None = None,
    min_periods: int = 0,
) -> Settled:
    """Judge a run that has gone ``periods_run`` periods, ending with the Poincare points
    ``points`` (n, K), at state ``x_end`` and time ``t_end``; continue it as the module
    text says.  ``tol``: how close Poincare points repeat (absolute, half backlashes);
    ``lyapunov``: the exponent over the same periods as ``points``, if the run had one;
    ``min_periods``: a chaotic or quasi-periodic verdict is not settled before the run has
    gone this far (the long budget of a border point: a chaotic transient has time to end).
    """
    run = {"method": method, "rtol": rtol, "atol": atol, "steps_per_period": steps_per_period}
    steps = _settling(
        system, points, x_end, t_end, periods_run, tol, budget, first_window, exponent,
        lyapunov, min_periods,
    )  # fmt: skip
    try:
        request = next(steps)
        while True:
            request = steps.send(_extend(system, *request, run, exponent))
    except StopIteration as done:
        return done.value


def settle_many(
    runs: list[tuple],
    *,
    method: str = "dop853",
    rtol: float = 1e-8,
    atol: float = 1e-10,
    steps_per_period: int = 512,
    budget: int = BUDGET,
    first_window: int = FIRST_WINDOW,
    exponent: bool = True,
    min_periods: int = 0,
) -> list[Settled]:
    """:func:`settle` for many runs at once, each ``(system, points, x_end, periods_run,
    tol)`` ending on a whole number of forcing periods (phase 0, as a finished run does).
    The same verdicts' logic, run by run; what changes is how the windows are run: each
    round, the windows of the runs still unsettled that share a model, a forcing
    frequency and a length are one batch of the compiled lockstep engine (a border run
    alone took its steps one point at a time: about five times the cost per period of
    the DI-SO in a group).  Each window starts at tau = 0, its phase (the model is
    periodic in the forcing period).  A method outside the compiled engine runs each
    window alone, as :func:`settle` does, and so does a run of a batch that stopped as a
    group (a step too small or the step budget spent: :data:`_GROUP_STOPS`).  A batch
    shares its steps, so a chaotic run's points depend on its batch-mates (its
    statistics, the verdict's evidence, do not)."""
    run = {"method": method, "rtol": rtol, "atol": atol, "steps_per_period": steps_per_period}
    steps = [
        _settling(
            system,
            points,
            x,
            0.0,
            before,
            tol,
            budget,
            first_window,
            exponent,
            None,
            min_periods,
        )  # fmt: skip
        for system, points, x, before, tol in runs
    ]
    out: list = [None] * len(runs)
    pending = {}
    for k, st in enumerate(steps):
        try:
            pending[k] = next(st)
        except StopIteration as done:
            out[k] = done.value
    while pending:
        batches: dict = {}
        for k, (_, _, length) in pending.items():
            system = runs[k][0]
            key = (system.module.__file__, float(system.omega), length)
            batches.setdefault(key, []).append(k)
        answers = {}
        for ks in batches.values():
            systems = [runs[k][0] for k in ks]
            xs = [pending[k][0] for k in ks]
            length = pending[ks[0]][2]
            answers.update(zip(ks, _extend_many(systems, xs, length, run, exponent), strict=True))
        pending = {}
        for k in sorted(answers):
            try:
                pending[k] = steps[k].send(answers[k])
            except StopIteration as done:
                out[k] = done.value
    return out


# Statuses a lockstep group shares: one run whose steps shrink to nothing, or that
# exhausts the step budget, stops every run of its group
_GROUP_STOPS = ("step too small", "too many steps")


def _extend_many(systems, xs, periods: int, run: dict, exponent: bool) -> list[tuple]:
    """:func:`_extend` of each system from its state at phase 0, one batch of the compiled
    engine where the method is native (else one at a time)."""
    if len(systems) == 1 or get_method(run["method"]).family != "native":
        pairs = zip(systems, xs, strict=True)
        return [_extend(s, x, 0.0, periods, run, exponent) for s, x in pairs]
    from ..integrate.run import Batch

    # looks vary in ways no map column does: the model's one library (hoist=False)
    spec = _window_spec(periods, run, exponent, 0.0, hoist=False)
    P = np.array([s.p for s in systems], dtype=float)
    res = integrate(Batch.of(systems[0].module, P), np.array(xs, dtype=float), spec)
    return [
        # a run of a group that stopped as a whole runs alone, as settle runs it
        _extend(system, xs[i], 0.0, periods, run, exponent)
        if res.status[i] in _GROUP_STOPS
        else _window(res, i, system, periods, run, exponent)
        for i, system in enumerate(systems)
    ]


def _window_spec(periods: int, run: dict, exponent: bool, t0: float, hoist=True) -> RunSpec:
    """The compiled engine's spec of a continued window of ``periods`` from ``t0``."""
    return RunSpec(
        method=run["method"],
        rtol=run["rtol"],
        atol=run["atol"],
        t0=t0,
        transient=0,
        periods=periods,
        steps_per_period=run["steps_per_period"],
        collect=("samples", "extremes", "exponent") if exponent else ("samples", "extremes"),
        lyapunov_periods=periods if exponent else 0,
        hoist=hoist,
    )


def _window(res, i: int, system, periods: int, run: dict, exponent: bool) -> tuple:
    """Run ``i`` of a window's result as :func:`_extend` gives it."""
    status, X = res.status[i], res.x[i]
    lyap = None
    if exponent and status == "ok":
        lyap = LyapunovEstimate.from_running(
            res.exponent[i], run["rtol"], run["atol"], res.label, system.period
        )
    return X[:periods].T, X[-1].copy(), status, lyap, (res.xmin[i], res.xmax[i])


def _settling(
    system, points, x_end, t_end, periods_run, tol, budget, first_window, exponent,
    lyapunov, min_periods,
):  # fmt: skip
    """:func:`settle`'s steps: a generator that yields each window it needs,
    ``(x_end, t_end, periods)``, is sent back what :func:`_extend` gives for it, and
    returns the :class:`Settled`."""
    x_end = np.asarray(x_end, dtype=float)
    w = Window(periods_run - points.shape[1], points, lyapunov)
    judged: list[dict] = []
    length, ext = first_window, None
    while True:
        done = _verdict(
            system, w, x_end, t_end, judged, periods_run, tol, budget, exponent, min_periods
        )
        if done is not None:
            return replace(done, extremes=ext)
        L = min(length, budget - periods_run)
        length *= 2
        pts, x_new, status, lyap, ext = yield (x_end, t_end, L)
        periods_run += L
        if status != "ok":
            motion = "divergent" if status == "divergent" else "undetermined"
            why = {"why": f"the continued run stopped: {status}"}
            v = Verdict(motion, None, periods_run, {"windows": judged} | why)
            return Settled(v, w.points[:, -KEEP:], x_end, t_end, None, None)
        w = Window(w.end, pts, lyap)
        x_end, t_end = x_new, t_end + L * system.period


def _verdict(system, w, x_end, t_end, judged, periods_run, tol, budget, exponent, min_periods):
    """The settled verdict after window ``w`` (appending its judgement), or None: go on."""
    orbit = _periodic(system, w, x_end, t_end, tol)
    if orbit is not None:
        return _settled_periodic(system, w, x_end, t_end, orbit, judged, periods_run, tol)
    if w.lyapunov is not None:
        judged.append(judge(system, w, tol))
        label = settled(judged)
        if label is not None and (periods_run >= min_periods or budget - periods_run < 100):
            motion = "chaotic" if label == "chaotic" else "quasi-periodic"
            return _done(system, w, x_end, t_end, motion, judged, periods_run)
    if budget - periods_run < 100:
        return _undetermined(system, w, x_end, t_end, judged, periods_run, exponent)
    return None


def _settled_periodic(system, w, x_end, t_end, orbit, judged, periods_run, tol) -> Settled:
    n = orbit.n
    gaps = np.max(np.abs(w.points[:, n:] - w.points[:, :-n]), axis=0)
    evidence = {
        "orbit": orbit.describe(),
        "repeat_tolerance": tol,
        "last_gap": float(gaps[-1]) if gaps.size else None,
        "converging": bool(gaps.size and gaps.max() > tol),
        "spread": spread(system, w.points),
        "windows": judged,
    }
    if not orbit.attracting:
        evidence["neutral"] = (
            "the orbit is one of a family: a multiplier is +1 within its error (a free "
            "motion, such as bodies turning inside their backlash with every mesh apart), "
            "the others inside the unit circle; the run's points repeat on it"
        )
    chaotic = [j for j in judged if j["label"] == "chaotic"]
    if chaotic:
        evidence["transient_chaos"] = {
            "chaotic_until_at_least": chaotic[-1]["window"][1],
            "periodic_by": periods_run,
            "text": (
                f"chaotic transient: chaotic up to period {chaotic[-1]['window'][1]}, on the "
                f"period-{n} orbit by period {periods_run}"
            ),
        }
    lyap = {
        "exponent": orbit.exponent(system.period),
        "uncertainty": 0.0,
        "method": "log max|mu| / (n T) of the shooting check's multipliers",
        "units": "per unit tau",
    }
    v = Verdict(f"period-{n}", n, periods_run, evidence)
    return Settled(v, w.points[:, -KEEP:], x_end, t_end, lyap, orbit)


def _lyap_summary(w: Window) -> dict | None:
    return None if w.lyapunov is None else w.lyapunov.describe()


def _done(system, w, x_end, t_end, motion, judged, periods_run) -> Settled:
    evidence = {"spread": spread(system, w.points), "windows": judged}
    v = Verdict(motion, None, periods_run, evidence)
    return Settled(v, w.points[:, -KEEP:], x_end, t_end, _lyap_summary(w), None, w.lyapunov)


def _undetermined(system, w, x_end, t_end, judged, periods_run, exponent) -> Settled:
    if not exponent:
        why = "no attracting periodic orbit found, and the exponent was not computed"
    elif judged:
        why = judged[-1].get("why") or (
            f"the last window reads {judged[-1]['label']}, the one before does not agree"
        )
    else:
        why = "no attracting periodic orbit found, and no window was judged"
    evidence = {"why": f"{why} (after {periods_run} periods)", "windows": judged}
    evidence["spread"] = spread(system, w.points)
    v = Verdict("undetermined", None, periods_run, evidence)
    return Settled(v, w.points[:, -KEEP:], x_end, t_end, _lyap_summary(w), None, w.lyapunov)


def per_coordinate(system: System, v: Verdict, extra: dict | None = None) -> dict:
    """coordinate -> :class:`Classification`: the attractor's motion and period, with the
    coordinate's spread (and the reason of an undetermined verdict) as its evidence;
    ``extra`` maps coordinates to more evidence (spectral peaks, say)."""
    spreads = v.evidence.get("spread", {})
    out = {}
    for c in system.coordinates:
        ev = {"spread": spreads.get(c), **((extra or {}).get(c) or {})}
        if "why" in v.evidence:
            ev["why"] = v.evidence["why"]
        out[c] = Classification(v.motion, v.period, ev)
    return out
