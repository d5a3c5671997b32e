"""Everything about one operating point: response, spectra, exponent and the verdict.

``analyse_point`` is the convenience call on top of :func:`simulate` and :func:`settle`;
sweeps call it (or :func:`analyse_trajectory` on a batch's trajectories) once per point.

The verdict belongs to the attractor (``verdict.py``): a period-n label rests on the
shooting check from the run's end state, a chaotic or quasi-periodic one on two
successive windows of the run continued from where it ended (``settle.py``), each with
its exponent and the 0-1 test; anything else is ``undetermined`` with its reason.  Each
mesh coordinate's :class:`Classification` carries the attractor's label and its own
spread (the extent of its Poincare cloud and its share of the widest).
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from ..integrate import Trajectory, get_method, simulate
from ..system import System
from .classify import Classification
from .lyapunov import LyapunovEstimate
from .record import Extremes, RunRecord
from .settle import BUDGET, FIRST_WINDOW, Settled, per_coordinate, settle
from .spectra import extremes, meshing_states, spectrum
from .verdict import Verdict

__all__ = ["PointResult", "analyse_point", "analyse_trajectory", "classification_tolerance"]


@dataclass(frozen=True)
class PointResult:
    """One operating point analysed, with its time series: the live object behind the
    :class:`~.record.RunRecord` that sweeps and stores keep (:meth:`record`).

    ``lyapunov`` is the last window's estimate with its running history (None for a
    periodic verdict: its exponent comes from the orbit's multipliers); ``verdict`` the
    attractor's; ``settled`` what the continued run gave (end state, last window's
    Poincare points, the exponent's summary); ``spectra`` per coordinate (None: computed
    on demand).
    """

    trajectory: Trajectory
    lyapunov: LyapunovEstimate | None
    classification: dict[str, Classification]
    spectra: dict | None = None
    verdict: Verdict | None = None
    settled: Settled | None = None

    def record(self, values: dict | None = None, *, start: str = "default", x0=None):
        """The :class:`~.record.RunRecord` of this point: its verdicts, extremes, Poincare
        points (copied), meshing shares, exponent's summary, spectral peaks and timings.

        ``values`` names the parameter values the caller varied (a sweep's one);
        ``start`` and ``x0`` say where the run started (None: the default state).
        """
        tr, st = self.trajectory, self.settled
        states = tr.system.states
        if st is not None:
            poincare = {s: st.points[k].copy() for k, s in enumerate(states)}
            x_final, lyap = st.x_final.copy(), st.lyapunov
        else:
            poincare = {s: tr.poincare[k].copy() for k, s in enumerate(states)}
            x_final, lyap = tr.x_final.copy(), None
        return RunRecord(
            values={k: float(v) for k, v in (values or {}).items()},
            status=tr.status,
            classification=dict(self.classification),
            extremes=self._extremes(),
            start=start,
            x0=None if x0 is None else np.array(x0, dtype=float),
            meshing_states=meshing_states(tr),
            lyapunov=lyap,
            spectra={c: self._spectrum(c).describe() for c in tr.system.coordinates},
            poincare=poincare,
            x_final=x_final,
            integration=tr.describe(),
            verdict=None if self.verdict is None else self.verdict.describe(),
        )

    def _extremes(self) -> dict:
        """Per state: over the last continued window when the run was continued (the
        attractor it settled on), else over the sampled window."""
        st = self.settled
        if st is not None and st.extremes is not None:
            lo, hi = st.extremes
            states = self.trajectory.system.states
            return {s: Extremes(float(hi[k]), float(lo[k])) for k, s in enumerate(states)}
        return {s: Extremes(e["max"], e["min"]) for s, e in extremes(self.trajectory).items()}

    def __repr__(self) -> str:
        tr = self.trajectory
        motion = self.verdict.motion if self.verdict is not None else "no verdict"
        return (
            f"PointResult({tr.system!r}: {motion}; "
            f"{tr.transient} + {tr.periods} periods, {tr.status})"
        )

    def summary(self) -> str:
        """A few lines to read: the model and values, the verdict with its evidence, the
        run, the extremes of each coordinate (:meth:`to_dict` has everything)."""
        import textwrap

        tr = self.trajectory
        ext = self._extremes()
        return "\n".join(
            [
                f"{tr.system!r}",
                textwrap.fill(verdict_line(self), 100, subsequent_indent="  "),
                f"run: {tr.method} {tr.tolerance}, {tr.transient} + {tr.periods} periods, "
                f"status {tr.status}, {tr.wall_time:.2f} s",
                "extremes: "
                + ", ".join(
                    f"{c} in [{ext[c].min}, {ext[c].max}]"
                    if ext[c].max is None
                    else f"{c} in [{ext[c].min:.4g}, {ext[c].max:.4g}]"
                    for c in tr.system.coordinates
                )
                + " (half backlashes)",
            ]
        )

    def describe(self, poincare: bool = True) -> dict:
        """The point's summary (its :meth:`record`) with the system's description."""
        rec = self.record()
        out = {
            "system": self.trajectory.system.describe(),
            "integration": rec.integration,
            "classification": {c: k.describe() for c, k in rec.classification.items()},
            "extremes": {s: e.to_dict() for s, e in rec.extremes.items()},
            "meshing_states": rec.meshing_states,
            "spectra": rec.spectra,
            "lyapunov": rec.lyapunov,
            "verdict": rec.verdict,
        }
        if poincare:
            out["poincare"] = {s: v.tolist() for s, v in rec.poincare.items()}
        return out

    def _spectrum(self, c: str):
        known = (self.spectra or {}).get(c)
        return known if known is not None else spectrum(self.trajectory, c)

    def to_dict(self, samples: bool = True) -> dict:
        """The header block (``provenance.provenance``) and everything of
        :meth:`describe`, with the time series when ``samples``."""
        from ..provenance import provenance

        out = provenance(self.trajectory.system) | self.describe()
        if samples:
            out["samples"] = {k: v for k, v in self.trajectory.to_dict().items() if k in ("t", "x")}
        return out

    def to_table(self) -> tuple[list, list]:
        """The sampled response, one row per sample (see ``Trajectory.to_table``)."""
        return self.trajectory.to_table()

    def save(self, path, **extra):
        """Write to ``path``: ``.json``, ``.csv`` or ``.mat`` (see ``solver/export.py``)."""
        from ..export import save

        return save(self, path, **extra)


def classification_tolerance(method: str, rtol: float) -> float:
    """How close Poincare points must come to count as the same, relative to the cloud."""
    if not get_method(method).adaptive:
        return 1e-3
    return max(1e-6, 1e3 * rtol)


def analyse_point(
    system: System,
    x0=None,
    *,
    method: str | None = None,
    rtol: float = 1e-8,
    atol: float = 1e-10,
    transient: int = 300,
    periods: int = 100,
    samples_per_period: int = 64,
    lyapunov_periods: int = FIRST_WINDOW,
    steps_per_period: int = 512,
    on_invalid: str = "warn",
    budget: int = BUDGET,
    transient_rtol: float | None = None,
) -> PointResult:
    """Simulate, then judge the attractor (see the module text).

    ``method`` defaults to the fastest that meets ``rtol`` (see :func:`simulate`).
    ``lyapunov_periods``: the first continued window, over which the exponent runs (each
    next window twice as long; 0: no exponent, so only periodic verdicts can settle).
    ``budget``: periods the verdict may take in all, counted from the run's start.
    ``transient_rtol``: a looser tolerance for the transient alone (:func:`simulate`).
    """
    tr = simulate(
        system,
        x0,
        method=method,
        rtol=rtol,
        atol=atol,
        transient=transient,
        periods=periods,
        samples_per_period=samples_per_period,
        steps_per_period=steps_per_period,
        on_invalid=on_invalid,
        transient_rtol=transient_rtol,
    )
    return analyse_trajectory(
        tr,
        rtol=rtol,
        atol=atol,
        lyapunov_periods=lyapunov_periods,
        steps_per_period=steps_per_period,
        on_invalid=on_invalid,
        budget=budget,
    )


def analyse_trajectory(
    tr,
    *,
    rtol: float = 1e-8,
    atol: float = 1e-10,
    lyapunov_periods: int = FIRST_WINDOW,
    steps_per_period: int = 512,
    on_invalid: str = "warn",
    budget: int = BUDGET,
) -> PointResult:
    """The analysis of :func:`analyse_point` on a simulated trajectory (from
    ``simulate`` or ``simulate_many``): the attractor's verdict from the run's end on,
    and each coordinate's spread."""
    system = tr.system
    coords = system.coordinates
    if tr.status != "ok":
        motion = "divergent" if tr.status == "divergent" else "undetermined"
        why = {"why": tr.message} if motion == "undetermined" else {}
        verdict = Verdict(motion, None, tr.transient + tr.periods, why)
        return PointResult(
            tr, None, {c: Classification(motion, None, why) for c in coords}, None, verdict
        )
    del on_invalid  # the continued windows record a valid-range exit as the first run did
    cloud = max(float(np.ptp(tr.poincare, axis=1).max()), 1.0)
    st = settle(
        system,
        tr.poincare,
        tr.x_final,
        tr.t_final,
        periods_run=tr.transient + tr.periods,
        tol=classification_tolerance(tr.method, rtol) * cloud,
        method=tr.method,
        rtol=rtol,
        atol=atol,
        steps_per_period=steps_per_period,
        budget=max(budget, tr.transient + tr.periods),
        first_window=max(lyapunov_periods, 100),
        exponent=lyapunov_periods > 0,
    )
    v = st.verdict
    if v.periods_run > tr.transient + tr.periods:
        tr = _closing_sample(tr, st, rtol, atol, steps_per_period)
    spectra = {c: spectrum(tr, c) for c in coords}
    verdicts = per_coordinate(
        system, v, {c: {"spectrum_peaks": spectra[c].peaks()} for c in coords}
    )
    return PointResult(tr, st.estimate, verdicts, spectra, v, st)


def _closing_sample(tr, st: Settled, rtol: float, atol: float, steps_per_period: int):
    """A run continued past its first window is shown where its verdict was reached: the
    time series, spectra and meshing shares of a point are resampled over as many periods
    as the first window sampled, from where the last continued window ended (a chaotic
    transient that ended on an orbit shows the orbit; the verdict's own extremes and
    Poincare points are those of its last window).  The first window's trajectory is kept
    if the resampling fails."""
    import warnings

    with warnings.catch_warnings():  # a valid-range exit was said by the first window
        warnings.simplefilter("ignore")
        again = simulate(
            tr.system,
            st.x_final,
            method=tr.method,
            rtol=rtol,
            atol=atol,
            transient=0,
            periods=tr.periods,
            samples_per_period=tr.samples_per_period,
            t0=st.t_final,
            steps_per_period=steps_per_period,
        )
    # the run's options (the transient's own tolerances, say) are still the run's
    return replace(again, options={**tr.options, **again.options}) if again.status == "ok" else tr


def verdict_line(point) -> str:
    """The verdict line of one analysed point (a ``PointResult``): the motion (one label
    when the coordinates agree) and its evidence: the periods run, the orbit's largest
    Floquet multiplier |μ| or the last window's exponent interval (per unit τ) and 0-1
    test K, the reason of an undetermined verdict, a chaotic transient (the title of a
    point's figure and :meth:`PointResult.summary`)."""
    coordinates = point.trajectory.system.coordinates
    cls = point.classification
    motions = {c: getattr(cls[c], "motion", str(cls[c])) for c in coordinates}
    if len(set(motions.values())) == 1:
        parts = [f"verdict: {next(iter(motions.values()))} ({', '.join(motions)})"]
    else:
        parts = ["verdict: " + ", ".join(f"{c} {m}" for c, m in motions.items())]
    verdict = getattr(point, "verdict", None)
    s = verdict.summary() if verdict is not None else {}
    if "periods_run" in s:
        parts.append(f"{s['periods_run']} periods run")
    if s.get("largest_multiplier") is not None:
        parts.append(f"largest |Floquet multiplier| {s['largest_multiplier']:.4f}")
    if "exponent_interval" in s:
        lo, hi = s["exponent_interval"]
        parts.append(f"largest Lyapunov exponent in [{lo:+.4f}, {hi:+.4f}] per unit τ")
    elif point.lyapunov is not None:
        lam = point.lyapunov
        parts.append(
            f"largest Lyapunov exponent {lam.exponent:+.4f} ± {lam.uncertainty:.4f} "
            f"per unit τ ({lam.periods} periods)"
        )
    if "zero_one_K" in s:
        parts.append(f"0-1 test K = {s['zero_one_K']:.2f}")
    if "two_trajectory_interval" in s:
        lo, hi = s["two_trajectory_interval"]
        agrees = " (the second test that agrees)" * (
            s.get("second_test") == "two-trajectory exponent"
        )
        parts.append(f"two-trajectory exponent in [{lo:+.4f}, {hi:+.4f}]{agrees}")
    if "transient_chaos" in s:
        parts.append(str(s["transient_chaos"].get("text", "chaotic transient")))
    if "why" in s:
        parts.append(f"why: {s['why']}")
    return "; ".join(parts)
