"""What a run needs and what it gives: :class:`RunSpec` in, :class:`RunResult` out.

Every engine (the compiled one of ``native/``, its NumPy/SciPy fallback) takes one
``RunSpec`` and returns one ``RunResult``; ``integrate()`` (``run.py``) is the front door.
A spec checks itself once, in its constructor, with the messages a user sees, so nothing
below it checks options again and nothing unchecked reaches the C.

Time modes. ``"tau"``: the non-dimensional time ``tau``; the excitation period is
``T = 2 pi / omega`` with ``omega`` the contract's forcing frequency, the same for every
point of a batch. ``"phase"``: the excitation phase ``s = omega tau`` (period ``2 pi``),
so points of one batch may have different ``omega`` (a frequency sweep in one call).

Samples are taken at ``t0 + (transient + k / samples_per_period) T``,
``k = 0 .. periods * samples_per_period`` (the last one closes the window); with
``samples_per_period = 1`` they are the Poincare (stroboscopic) points.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields, replace

import numpy as np

from .methods import REGISTRY

__all__ = ["COLLECT", "INT64_MAX", "RunResult", "RunSpec", "TIME_MODES", "VALID_RANGE"]

TIME_MODES = ("tau", "phase")
# What a run keeps besides its work counters: the samples; each state's smallest and
# largest value over the sampled window, at every accepted step; the running largest
# Lyapunov exponent from a tangent vector (Benettin et al. 1980, renormalised each period);
# the monodromy matrix of the whole run from the variational equations (one tangent per
# state: each point runs once per state, the tangent starting from that unit vector).
COLLECT = ("samples", "extremes", "exponent", "monodromy")
# At the force law's valid range (the contract's bounds): record the first exit and go on,
# stop the point there, or do not check.
VALID_RANGE = ("record", "stop", "ignore")
INT64_MAX = 2**63 - 1
_MOST_STEPS = 2**53  # step budgets above this cannot be counted exactly in a double
_MOST_GROUP = 4096


def _whole(name: str, value, low: int, high: int = _MOST_STEPS) -> int:
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
        if isinstance(value, (float, np.floating)) and float(value).is_integer():
            value = int(value)
        else:
            raise ValueError(f"{name} must be a whole number, got {value!r}")
    if not low <= value <= high:
        raise ValueError(f"{name} must be a whole number in [{low}, {high}], got {value}")
    return int(value)


def _positive(name: str, value, most: float = math.inf) -> float:
    try:
        value = float(value)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a positive number, got {value!r}") from None
    if not (value > 0 and math.isfinite(value)):
        raise ValueError(f"{name} must be a positive number, got {value}")
    if value > most:
        raise ValueError(f"{name} must be at most {most:g}, got {value:g}")
    return value


@dataclass(frozen=True, kw_only=True)
class RunSpec:
    """One run's options, checked once.

    Attributes
    ----------
    method : str
        A compiled method of the registry (``methods.py``): ``dop853``, ``dopri5`` or
        ``rk4`` (fixed step, ``steps_per_period`` steps, time mode ``"tau"`` only).
    rtol, atol : float
        Error tolerances of the adaptive methods; ``0 < rtol <= 0.1``, ``atol > 0``.
    time : {"tau", "phase"}
        See the module text.
    t0 : float
        Start time (in the time mode's unit).
    transient, periods, samples_per_period : int
        Forcing periods run before sampling, periods sampled, samples per period.
    steps_per_period : int
        Fixed-step methods only: a multiple of ``samples_per_period``.
    collect : tuple of str
        What to keep, from :data:`COLLECT`.
    lyapunov_periods : int
        With ``"exponent"`` collected: the last ``lyapunov_periods`` periods carry the
        tangent vector (at most ``transient + periods``).
    seed : int
        Seed of the tangent vector's random start.
    valid_range : {"record", "stop", "ignore"}
        What to do at the force law's valid range (the contract's bounds).
    bound : float
        A state whose magnitude passes ``bound`` is reported divergent.
    max_steps : int
        Step budget per point.
    lockstep, group, dense : bool, int, bool
        Compiled engine only: groups of ``group`` points share time and step size;
        ``dense`` interpolates samples with DOP853's dense output instead of shortening
        steps to land on them. Neither changes what is computed beyond the tolerances.
    hoist : bool
        Compiled engine only: the parameters equal across the batch are compiled in (a
        library per set of them, hoisting what depends on them alone out of the point
        loop) for one point and for a batch long enough to pay for the compile
        (``native.engine.batch_shared``); False: the library for any batch, one per
        model, always.
    """

    method: str = "dop853"
    rtol: float = 1e-8
    atol: float = 1e-10
    time: str = "tau"
    t0: float = 0.0
    transient: int = 300
    periods: int = 100
    samples_per_period: int = 1
    steps_per_period: int = 256
    collect: tuple[str, ...] = ("samples",)
    lyapunov_periods: int = 0
    seed: int = 0
    valid_range: str = "record"
    bound: float = 1e3
    max_steps: int = 50_000_000
    lockstep: bool = True
    group: int = 64
    dense: bool = True
    hoist: bool = True

    def __post_init__(self):
        put = object.__setattr__
        record = REGISTRY.get(self.method)
        if record is None or record.family != "native":
            names = ", ".join(m.name for m in REGISTRY.values() if m.family == "native")
            raise ValueError(f"method {self.method!r} is not a compiled method; methods: {names}")
        put(self, "rtol", _positive("rtol", self.rtol, most=0.1))
        put(self, "atol", _positive("atol", self.atol))
        if self.time not in TIME_MODES:
            raise ValueError(f"time {self.time!r} is unknown; time modes: {', '.join(TIME_MODES)}")
        if self.time == "phase" and not record.adaptive:
            raise ValueError(f"method {self.method!r} runs in tau only; use dop853 or dopri5")
        t0 = float(self.t0)
        if not math.isfinite(t0):
            raise ValueError(f"t0 must be a finite number, got {self.t0}")
        put(self, "t0", t0)
        put(self, "transient", _whole("transient", self.transient, 0))
        put(self, "periods", _whole("periods", self.periods, 1))
        put(self, "samples_per_period", _whole("samples_per_period", self.samples_per_period, 1))
        put(self, "steps_per_period", _whole("steps_per_period", self.steps_per_period, 1))
        samples = self.periods * self.samples_per_period + 1
        if samples > _MOST_STEPS:
            raise ValueError(
                f"{self.periods} periods at {self.samples_per_period} samples each are "
                f"{samples:.3g} samples, above the {_MOST_STEPS:.3g} a run can index"
            )
        if not record.adaptive:
            spp, steps = self.samples_per_period, self.steps_per_period
            if steps < spp or steps % spp:
                raise ValueError(
                    f"steps_per_period ({steps}) must be a multiple of samples_per_period "
                    f"({spp}) for {self.method}"
                )
            if (self.transient + self.periods) * steps > _MOST_STEPS:
                raise ValueError(
                    f"{self.transient + self.periods} periods of {steps} fixed steps are "
                    "more steps than a run can count; lower steps_per_period or periods"
                )
        collect = tuple(self.collect)
        unknown = [c for c in collect if c not in COLLECT]
        if unknown or not collect:
            raise ValueError(f"collect {collect!r}: give one or more of {', '.join(COLLECT)}")
        put(self, "collect", tuple(c for c in COLLECT if c in collect))
        most = self.transient + self.periods
        put(self, "lyapunov_periods", _whole("lyapunov_periods", self.lyapunov_periods, 0, most))
        if ("exponent" in collect) != (self.lyapunov_periods > 0):
            raise ValueError(
                "collecting the exponent needs lyapunov_periods > 0, and lyapunov_periods "
                "> 0 needs 'exponent' collected"
            )
        if "monodromy" in collect and ("exponent" not in collect or self.lyapunov_periods != most):
            raise ValueError(
                "collecting the monodromy needs 'exponent' collected with lyapunov_periods "
                f"= transient + periods ({most}): the tangent runs from the start"
            )
        put(self, "seed", _whole("seed", self.seed, 0, 2**32 - 1))
        if self.valid_range not in VALID_RANGE:
            raise ValueError(
                f"valid_range {self.valid_range!r} is unknown; choose {', '.join(VALID_RANGE)}"
            )
        put(self, "bound", _positive("bound", self.bound))
        put(self, "max_steps", _whole("max_steps", self.max_steps, 1))
        put(self, "group", _whole("group", self.group, 1, _MOST_GROUP))
        put(self, "lockstep", bool(self.lockstep))
        put(self, "dense", bool(self.dense))
        put(self, "hoist", bool(self.hoist))

    @property
    def adaptive(self) -> bool:
        return REGISTRY[self.method].adaptive

    @property
    def n_samples(self) -> int:
        """Samples per point: ``periods * samples_per_period + 1``."""
        return self.periods * self.samples_per_period + 1

    def sample_times(self, period: float) -> np.ndarray:
        """The sample times for an excitation period ``period`` (``2 pi`` in the phase)."""
        k = np.arange(self.n_samples)
        return self.t0 + (self.transient + k / self.samples_per_period) * period

    def with_(self, **changes) -> RunSpec:
        """A copy with ``changes``, checked again."""
        return replace(self, **changes)

    def to_dict(self) -> dict:
        return {f.name: getattr(self, f.name) for f in fields(self)}


@dataclass(frozen=True)
class RunResult:
    """What one call of an engine gives for N points.

    Attributes
    ----------
    t : ndarray, shape (K,)
        Sample times in the spec's time mode (the phase ``s`` is the same for every point:
        divide by each point's ``omega`` for ``tau``).
    x : ndarray, shape (N, K, n), or None
        Samples, when ``"samples"`` was collected.
    xmin, xmax : ndarray, shape (N, n), or None
        Extremes over the sampled window at every accepted step, when collected.
    exponent : ndarray, shape (N, lyapunov_periods), or None
        Running largest Lyapunov exponent (per unit tau) after each tangent period.
    nfev, nsteps : ndarray of int64, shape (N,)
    status : tuple of str
        Per point: ``ok``, ``divergent``, ``too many steps``, ``not finite``, ``step too
        small``, ``left the valid range`` (with ``valid_range="stop"``).
    t_fail : ndarray, shape (N,)
        Where a point stopped early (its time mode), else its end.
    monodromy : ndarray, shape (N, n, n), or None
        ``d x(end) / d x(start)`` of each point, from the variational equations (its
        columns: the tangents started from the unit vectors), when collected; NaN where the
        point's run failed.
    tangent : ndarray, shape (N, n + 1), or None
        With a tangent start per point (the engines' ``tangent0``): each point's tangent at
        the end (unit length) and its log growth from the start; how ``monodromy`` is built.
    exits : ndarray, shape (N, 3), or None
        ``(tau, state index, value)`` of each point's first exit from the valid range
        (``tau`` NaN: none), located on the accepted steps; None where not checked.
    method, backend : str
        The method that ran and the engine: ``"native"`` or ``"numpy"``.
    wall_time, compile_seconds : float
    """

    t: np.ndarray
    x: np.ndarray | None
    nfev: np.ndarray
    nsteps: np.ndarray
    status: tuple[str, ...]
    t_fail: np.ndarray
    method: str
    backend: str
    xmin: np.ndarray | None = None
    xmax: np.ndarray | None = None
    exponent: np.ndarray | None = None
    exits: np.ndarray | None = None
    monodromy: np.ndarray | None = None
    tangent: np.ndarray | None = None
    wall_time: float = 0.0
    compile_seconds: float = 0.0

    @property
    def label(self) -> str:
        """How the run was made, for reports: 'compiled DOP853', 'NumPy fallback DOPRI5'."""
        where = "compiled" if self.backend == "native" else "NumPy fallback"
        return f"{where} {self.method.upper()}"
