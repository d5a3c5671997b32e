"""Everything about one operating point: response, spectra, exponent and verdicts.

``analyse_point`` is the convenience call on top of :func:`simulate`,
:func:`largest_lyapunov` and :func:`classify_points`; sweeps call it once per point.

Adaptive Poincare sample: a coordinate whose verdict from the sampled window is not
period-n (chaotic, quasi-periodic or undetermined) is classified again on at least
``dimension_points`` (default 400) Poincare points, the run being continued from its end
state for the missing periods: the correlation dimension that tells a torus section from
a strange attractor is unreliable on 100 points.  The evidence records the count
(``poincare_points``, ``extended_from``); ``dimension_points=0`` keeps the window's
points and the evidence states the limit instead (``sample_limit``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..integrate import Trajectory, get_method, simulate
from ..system import System
from .classify import DIMENSION_POINTS, Classification, classify_points
from .lyapunov import LyapunovEstimate, largest_lyapunov
from .record import Extremes, RunRecord
from .spectra import extremes, meshing_states, spectrum

__all__ = ["PointResult", "analyse_point", "analyse_trajectory", "classification_tolerance"]


@dataclass(frozen=True)
class PointResult:
    """One operating point analysed, with its time series: the live object behind the
    :class:`~.record.RunRecord` that sweeps and stores keep (:meth:`record`).

    ``lyapunov`` is the estimate with its running history (or None); ``spectra`` the
    spectra the verdicts were drawn from, per coordinate (None: computed on demand).
    """

    trajectory: Trajectory
    lyapunov: LyapunovEstimate | None
    classification: dict[str, Classification]
    spectra: dict | None = None

    def record(self, values: dict | None = None, *, start: str = "default", x0=None):
        """The :class:`~.record.RunRecord` of this point: its verdicts, extremes, Poincare
        points (copied), meshing shares, exponent's summary, spectral peaks and timings.

        ``values`` names the parameter values the caller varied (a sweep's one);
        ``start`` and ``x0`` say where the run started (None: the default state).
        """
        tr = self.trajectory
        return RunRecord(
            values={k: float(v) for k, v in (values or {}).items()},
            status=tr.status,
            classification=dict(self.classification),
            extremes={s: Extremes(e["max"], e["min"]) for s, e in extremes(tr).items()},
            start=start,
            x0=None if x0 is None else np.array(x0, dtype=float),
            meshing_states=meshing_states(tr),
            lyapunov=None if self.lyapunov is None else self.lyapunov.describe(),
            spectra={c: self._spectrum(c).describe() for c in tr.system.coordinates},
            poincare={s: tr.poincare[k].copy() for k, s in enumerate(tr.system.states)},
            x_final=tr.x_final.copy(),
            integration=tr.describe(),
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
        }
        if poincare:
            out["poincare"] = {s: v.tolist() for s, v in rec.poincare.items()}
        return out

    def _spectrum(self, c: str):
        known = (self.spectra or {}).get(c)
        return known if known is not None else spectrum(self.trajectory, c)

    def to_dict(self, samples: bool = True) -> dict:
        """Everything of :meth:`describe`, with the time series when ``samples``."""
        out = self.describe()
        if samples:
            out["samples"] = {k: v for k, v in self.trajectory.to_dict().items() if k in ("t", "x")}
        return out

    def to_table(self) -> tuple[list, list]:
        """The sampled response, one row per sample (see ``Trajectory.to_table``)."""
        return self.trajectory.to_table()

    def save(self, path):
        """Write to ``path``: ``.json``, ``.csv`` or ``.mat`` (see ``solver/export.py``)."""
        from ..export import save

        return save(self, path)


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
    lyapunov_periods: int = 200,
    steps_per_period: int = 512,
    on_invalid: str = "warn",
    dimension_points: int = DIMENSION_POINTS,
) -> PointResult:
    """Simulate, estimate the largest exponent from the end state, classify each mesh.

    ``method`` defaults to the fastest that meets ``rtol`` (see :func:`simulate`).
    ``dimension_points``: Poincare points a non-periodic verdict is decided on (the run
    is extended when the window has fewer; 0: never extend, see the module docstring).
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
    )
    return analyse_trajectory(
        tr,
        rtol=rtol,
        atol=atol,
        lyapunov_periods=lyapunov_periods,
        steps_per_period=steps_per_period,
        on_invalid=on_invalid,
        dimension_points=dimension_points,
    )


def analyse_trajectory(
    tr,
    *,
    rtol: float = 1e-8,
    atol: float = 1e-10,
    lyapunov_periods: int = 200,
    steps_per_period: int = 512,
    on_invalid: str = "warn",
    dimension_points: int = DIMENSION_POINTS,
) -> PointResult:
    """The analysis of :func:`analyse_point` on a simulated trajectory (from
    ``simulate`` or ``simulate_many``): the exponent from its end state, then the
    verdict per mesh, with the sample extended for a non-periodic one."""
    system = tr.system
    lyap = None
    if tr.status == "ok" and lyapunov_periods > 0:
        # The variational equations at the run's own tolerances (compiled DOP853, or
        # CVODES without a compiler: see lyapunov.py).
        try:
            lyap = largest_lyapunov(
                system,
                tr.x_final,
                t0=tr.t_final,
                periods=lyapunov_periods,
                rtol=max(rtol, 1e-13),
                atol=max(atol, 1e-15),
            )
        except (FloatingPointError, RuntimeError):
            lyap = None
    tol = classification_tolerance(tr.method, rtol)
    verdicts = {}
    if tr.status == "invalid":
        why = {"why": tr.message}
        return PointResult(
            tr, None, {c: Classification("undetermined", None, why) for c in system.coordinates}
        )
    spectra = {c: spectrum(tr, c) for c in system.coordinates} if tr.status == "ok" else None
    for c in system.coordinates:
        i, j = system.index(c), system.velocity_index(c)
        points = tr.poincare[[i, j]]
        verdicts[c] = classify_points(
            points,
            tol=tol,
            lyapunov=lyap,
            divergent=tr.status == "divergent",
            period=system.period,
            spectrum_peaks=spectra[c].peaks() if spectra else None,
        )
    unsettled = [c for c, k in verdicts.items() if k.period is None and k.motion != "divergent"]
    more = dimension_points - tr.poincare.shape[1]
    if unsettled and more > 0 and tr.status == "ok":
        ext = simulate(
            system,
            tr.x_final,
            method=tr.method,
            rtol=rtol,
            atol=atol,
            t0=tr.t_final,
            transient=0,
            periods=more,
            samples_per_period=1,
            steps_per_period=steps_per_period,
            on_invalid=on_invalid,
        )
        if ext.status == "ok":
            poincare = np.concatenate([tr.poincare, ext.poincare], axis=1)
            for c in unsettled:
                i, j = system.index(c), system.velocity_index(c)
                k = classify_points(
                    poincare[[i, j]],
                    tol=tol,
                    lyapunov=lyap,
                    period=system.period,
                    spectrum_peaks=verdicts[c].evidence.get("spectrum_peaks"),
                )
                k.evidence["extended_from"] = int(tr.poincare.shape[1])
                verdicts[c] = k
    return PointResult(tr, lyap, verdicts, spectra)
