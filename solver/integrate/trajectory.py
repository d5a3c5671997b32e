"""A sampled response: what :func:`~.simulate.simulate` returns."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..system import System

__all__ = ["Trajectory"]


@dataclass(frozen=True)
class Trajectory:
    """A sampled response.

    Attributes
    ----------
    t : ndarray, shape (K,)
        Sample times (non-dimensional, tau) of the sampled window.
    x : ndarray, shape (n, K)
        States at ``t``.
    samples_per_period : int
        Samples per forcing period; ``x[:, ::samples_per_period]`` are Poincare points.
    status : str
        ``ok``, ``divergent`` (a state passed ``bound``), ``invalid`` (left the force
        law's valid range with ``on_invalid="error"``) or ``failed``.
    """

    system: System
    method: str
    rtol: float
    atol: float
    transient: int
    periods: int
    samples_per_period: int
    t: np.ndarray
    x: np.ndarray
    x_final: np.ndarray
    t_final: float
    status: str
    message: str
    nfev: int
    nsteps: int
    wall_time: float
    boundary_crossings: int | None = None  # located crossings (SciPy back ends only)
    left_valid_range: tuple | None = None  # (tau, state, value) of the first exit
    options: dict = field(default_factory=dict)

    @property
    def period(self) -> float:
        return self.system.period

    @property
    def poincare(self) -> np.ndarray:
        """Stroboscopic points at the start of each sampled period, shape (n, periods)."""
        return self.x[:, : self.periods * self.samples_per_period : self.samples_per_period]

    def coordinate(self, name: str) -> np.ndarray:
        return self.x[self.system.index(name)]

    def velocity(self, coordinate: str) -> np.ndarray:
        """The time derivative of mesh coordinate ``coordinate``."""
        return self.x[self.system.velocity_index(coordinate)]

    @property
    def tolerance(self) -> str:
        """``rtol 1e-08``, with the transient's own when it had one (``transient_rtol``)."""
        loose = self.options.get("transient_rtol")
        return f"rtol {self.rtol:g}" + ("" if loose is None else f" (transient {loose:g})")

    def __repr__(self) -> str:
        return (
            f"Trajectory({self.system!r}: {self.method}, {self.transient} + {self.periods} "
            f"periods x {self.samples_per_period} samples, {len(self.x)} states, {self.status})"
        )

    def summary(self) -> str:
        """A few lines: the model and values, the run, how it ended."""
        exit_ = self.left_valid_range
        return "\n".join(
            [
                repr(self.system),
                f"{self.method} {self.tolerance} atol {self.atol:g}: {self.transient} "
                f"periods discarded, {self.periods} sampled ({self.samples_per_period} per "
                f"period, τ {self.t[0]:.6g} to {self.t[-1]:.6g})"
                if self.t.size
                else "",
                f"status {self.status}{': ' + self.message if self.message else ''}; "
                f"{self.nfev} evaluations, {self.nsteps} steps, {self.wall_time:.2f} s",
            ]
            + (
                [f"left the valid range at τ = {exit_[0]:.6g} ({exit_[1]} = {exit_[2]:.4g})"]
                if exit_
                else []
            )
        )

    def describe(self) -> dict:
        return {
            "method": self.method,
            "rtol": self.rtol,
            "atol": self.atol,
            "transient_periods": self.transient,
            "sampled_periods": self.periods,
            "samples_per_period": self.samples_per_period,
            "status": self.status,
            "message": self.message,
            "nfev": self.nfev,
            "nsteps": self.nsteps,
            "wall_time_s": self.wall_time,
            "boundary_crossings": self.boundary_crossings,
            "left_valid_range": None
            if self.left_valid_range is None
            else dict(zip(("tau", "state", "value"), self.left_valid_range, strict=True)),
            "options": self.options,
        }

    def to_dict(self, samples: bool = True) -> dict:
        """The run's settings and outcome, with the samples (``t`` and each state) as
        NumPy arrays (a long run holds millions of them; ``solver/export.py`` writes them
        in blocks, and ``gearsym.solver._json.dumps`` takes them), after the header block
        of every result file (``solver/provenance.py``)."""
        from ..provenance import provenance

        out = provenance(self.system) | {
            "system": self.system.describe(),
            "integration": self.describe(),
        }
        if samples:
            out["t"] = self.t
            out["x"] = {s: self.x[k] for k, s in enumerate(self.system.states)}
        return out

    def to_table(self) -> tuple[list, np.ndarray]:
        """One row per sample: tau and every state (an array, one row per sample)."""
        return ["tau", *self.system.states], np.vstack([self.t, self.x]).T

    def save(self, path, **extra):
        """Write to ``path``: ``.json``, ``.csv`` or ``.mat`` (see ``solver/export.py``)."""
        from ..export import save

        return save(self, path, **extra)
