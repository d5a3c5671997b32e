"""One compiled run: :func:`run_compiled` fills the job of ``gs_integrate`` and reads it back.

Every compiled run -- one point on its own steps, lockstep groups, the excitation phase,
a map with its extremes and Lyapunov exponent -- is one call of the one C entry
(``native_*.c``) with a :class:`~.abi.Job` built from a :class:`~..spec.RunSpec`; what
differs between them is data in the job:

* ``group`` and ``batched``: ``spec.lockstep`` groups of ``spec.group`` points sharing
  time and step size, the excitation computed once per stage for a group; otherwise one
  point at a time on its own steps;
* ``time_mode``: ``tau`` (period ``T = 2 pi / omega``, one ``omega`` for the batch) or the
  phase ``s = omega tau`` (period ``2 pi``, ``dX/ds = f(s / omega, X) / omega``);
* ``period_stops``: with the extremes or the exponent collected the run is the
  stroboscopic map iterated period by period: it stops at every period from ``t0``
  (the tangent vector is renormalised at each stop: Benettin, Galgani, Giorgilli and
  Strelcyn 1980, Meccanica 15), then at every sample of the window;
* ``dense``: lockstep DOP853 runs that keep only samples interpolate them with the
  seventh-order dense output instead of shortening steps to land on them (a point on its
  own steps always lands on them).

``shared``: for one point, and for a batch long enough to pay for its own library
(:func:`batch_shared`), the parameters equal in every row of ``P`` are compiled in as
such (``build.library(..., shared=...)``), so the generated C may hoist what depends
only on them out of the point loop; any other batch runs with the model's one library.
"""

from __future__ import annotations

import time

import numpy as np

from ...contract import Contract
from ..spec import RunResult, RunSpec
from . import abi
from .build import library

__all__ = ["HOIST_FROM", "STATUS", "batch_shared", "run_compiled", "shared_parameters"]

STATUS = {
    0: "ok",
    1: "divergent",
    2: "too many steps",
    3: "not finite",
    4: "step too small",
    5: "left the valid range",
}
_METHODS = {"dopri5": 0, "dop853": 1, "rk4": 2}
_TIME = {"tau": 0, "phase": 1}
_RANGE = {"record": 0, "stop": 1, "ignore": 2}


def shared_parameters(P: np.ndarray) -> tuple[int, ...]:
    """Indices of the columns of ``P`` (N, n_p) where every row equals the first."""
    return tuple(int(k) for k in np.flatnonzero(np.all(P == P[:1], axis=0)))


# A batch's own library (the parameters it shares compiled in, ``build.library``) pays
# for its compile only on a long batch.  Measured on 2 cores, the torsional DI-SO, 40
# points of 200 + 100 periods at -O3, medians of 3: 0.79 ms a point with its own library
# against 1.05 with the model's one library (1.80 against 2.25 with the exponent's
# tangent), about 1 us a point and period, for a compile of about 1.1 s; the models of
# 22 and 30 states gain nothing (4.8 against 4.7 ms, 18.9 against 21.5).  A first
# reproduce compiled 16 such libraries, none of whose batches ran long enough to pay.
HOIST_FROM = 1_000_000  # points x periods of a batch that gets its own library


def batch_shared(module, P: np.ndarray, spec) -> tuple[int, ...]:
    """The ``shared`` of the library a batch at the rows of ``P`` runs with
    (``build.library``): every parameter for one point or copies of one (the one-point
    library of a sweep's runs, a monodromy's tangents as copies); the parameters the
    rows share for a long batch of a smooth model (:data:`HOIST_FROM`); else none, the
    model's one library for any batch (a piecewise model runs its points one at a time:
    nothing to hoist)."""
    P = np.atleast_2d(P)
    if not spec.hoist:
        return ()
    shared = shared_parameters(P)
    if len(shared) == P.shape[1]:  # one point, or copies of one (its starts, tangents)
        return shared
    work = P.shape[0] * (spec.transient + spec.periods)
    if work < HOIST_FROM or Contract.of(module).piecewise:
        return ()
    return shared


def _tangent_start(n: int, seed: int) -> np.ndarray:
    from .fallback import tangent_start  # the fallback starts from the same vector

    return np.ascontiguousarray(tangent_start(n, seed), dtype=float)


def _inputs(contract: Contract, P, X0) -> tuple[np.ndarray, np.ndarray]:
    n, n_p = len(contract.states), len(contract.parameters)
    P = np.ascontiguousarray(np.atleast_2d(np.asarray(P, dtype=float)))
    X0 = np.ascontiguousarray(np.atleast_2d(np.asarray(X0, dtype=float)))
    if P.ndim != 2 or P.shape[1] != n_p or P.shape[0] < 1 or X0.shape != (P.shape[0], n):
        raise ValueError(
            f"P must be (N, {n_p}) and X0 (N, {n}) with N >= 1; got {P.shape} and {X0.shape}"
        )
    for name, a in (("P", P), ("X0", X0)):
        if not np.all(np.isfinite(a)):
            raise ValueError(
                f"{name} holds a NaN or infinite value; every parameter and initial "
                "state must be a finite number"
            )
    return P, X0


def _period(contract: Contract, P: np.ndarray, spec: RunSpec) -> tuple[float, int]:
    """The excitation period in the time mode and the forcing frequency's column."""
    iw = contract.parameters.index(contract.forcing_frequency)
    omega = P[:, iw]
    if not np.all(omega > 0):
        raise ValueError(f"{contract.forcing_frequency} must be positive at every point")
    if spec.time == "phase":
        return 2.0 * np.pi, iw
    if np.ptp(omega) != 0.0:
        raise ValueError(
            f"{contract.forcing_frequency} must be the same for every point in time mode "
            "'tau'; use time='phase' for points of different forcing frequency"
        )
    return 2.0 * np.pi / float(omega[0]), iw


def run_compiled(module, P, X0, spec: RunSpec, tangent0=None, monodromy=False) -> RunResult:
    """Integrate every row ``P[i]`` (N, n_p) from ``X0[i]`` (N, n) of ``module`` as
    ``spec`` says, in the compiled engine.  ``tangent0`` (N, n), with the exponent
    collected from the run's start: each point's tangent start (default one unit vector
    drawn from ``spec.seed`` for all), and the result's ``tangent`` gives its end.
    ``monodromy``: the library with the matrix of tangents (``build.monodromy_library``),
    ``tangent0`` (N, n * n) each point's matrix, row-major, and ``tangent`` its end (the
    matrix scaled to unit norm, then its log growth).

    Returns a :class:`~..spec.RunResult` (``backend="native"``; ``exits`` in tau, None
    with ``valid_range="ignore"``).  Raises ``ValueError`` on inputs the spec cannot run,
    :class:`~.build.NativeUnavailable` without a working compiler, ``MemoryError`` when
    the work arrays cannot be allocated.
    """
    started = time.perf_counter()
    contract = Contract.of(module)
    P, X0 = _inputs(contract, P, X0)
    period, iw = _period(contract, P, spec)
    N, n = X0.shape
    collect = set(spec.collect)
    tangent = "exponent" in collect
    m = n * n if monodromy else n  # the tangent block's length
    if tangent0 is not None or monodromy:
        tangent0 = np.ascontiguousarray(tangent0, dtype=float)
        if (
            not tangent
            or tangent0.shape != (N, m)
            or spec.lyapunov_periods != (spec.transient + spec.periods)
        ):
            raise ValueError(
                f"tangent0 must be ({N}, {m}), with the exponent collected from the start"
            )
    kind = "monodromy" if monodromy else tangent
    lib, facts = library(module, variational=kind, shared=batch_shared(module, P, spec))
    K, L = spec.n_samples, spec.lyapunov_periods
    check = spec.valid_range != "ignore"
    bounds = np.full(n, np.inf)
    for i, b in contract.valid_bounds():
        bounds[i] = b
    out = {
        "P": P,
        "X0": X0,
        "bounds": bounds if check else None,
        "tangent0": _tangent_start(n, spec.seed) if tangent and tangent0 is None else tangent0,
        "x": np.empty((N, K, n)) if "samples" in collect else None,
        "xmin": np.empty((N, n)) if "extremes" in collect else None,
        "xmax": np.empty((N, n)) if "extremes" in collect else None,
        "exponent": np.empty((N, L)) if tangent else None,
        "tangent": np.empty((N, m + 1)) if tangent0 is not None else None,
        "nfev": np.zeros(N, dtype=np.int64),
        "nsteps": np.zeros(N, dtype=np.int64),
        "status": np.zeros(N, dtype=np.int32),
        "t_fail": np.zeros(N),
        "exits": np.full((N, 3), np.nan) if check else None,
    }
    lengths = {
        "P": N * P.shape[1],
        "X0": N * n,
        "bounds": n,
        "tangent0": n if tangent0 is None else N * m,
        "x": N * K * n,
        "xmin": N * n,
        "xmax": N * n,
        "exponent": N * L,
        "tangent": N * (m + 1),
        "nfev": N,
        "nsteps": N,
        "status": N,
        "t_fail": N,
        "exits": 3 * N,
    }
    flags = (
        abi.FLAGS["dense"] * (spec.dense and spec.lockstep)
        | abi.FLAGS["batched"] * spec.lockstep
        | abi.FLAGS["period_stops"] * bool(collect & {"extremes", "exponent"})
    )
    ints = {
        "abi": abi.ABI_VERSION,
        "n_points": N,
        "n_states": n,
        "n_params": P.shape[1],
        "group": spec.group if spec.lockstep else 1,
        "transient": spec.transient,
        "periods": spec.periods,
        "samples_per_period": spec.samples_per_period,
        "steps_per_period": spec.steps_per_period,
        "lyapunov_periods": L,
        "max_steps": spec.max_steps,
        "method": _METHODS[spec.method],
        "time_mode": _TIME[spec.time],
        "omega_index": iw,
        "valid_range": _RANGE[spec.valid_range],
        "flags": flags,
    }
    doubles = {
        "t0": spec.t0,
        "period": period,
        "rtol": spec.rtol,
        "atol": spec.atol,
        "bound": spec.bound,
    }
    arrays = {k: v for k, v in out.items() if v is not None}
    job, keep = abi.fill(ints, doubles, arrays, {k: lengths[k] for k in arrays})
    abi.call(lib, job)
    del keep
    exits = out["exits"]
    if exits is not None and spec.time == "phase":
        exits[:, 0] /= P[:, iw]  # the phase s = omega tau, back to tau
    return RunResult(
        t=spec.sample_times(period),
        x=out["x"],
        nfev=out["nfev"],
        nsteps=out["nsteps"],
        status=tuple(STATUS[int(s)] for s in out["status"]),
        t_fail=out["t_fail"],
        method=spec.method,
        backend="native",
        xmin=out["xmin"],
        xmax=out["xmax"],
        exponent=out["exponent"],
        exits=exits,
        tangent=out["tangent"],
        wall_time=time.perf_counter() - started,
        compile_seconds=facts["seconds"],
    )
