"""The front door of batched runs: ``integrate(target, x0, spec) -> RunResult``.

One point (a :class:`~..system.System`) or many (a :class:`Batch`: one generated model,
a parameter matrix) are integrated as one :class:`~.spec.RunSpec` says, by the compiled
engine (``native/``) or, without a compiler, by its one NumPy/SciPy fallback
(``native/fallback.py``). Which one runs is decided once, in the calling process, with one
warning line; ``workers > 1`` splits the points over as many processes through the one
executor (``solver/executor.py``), each task a frozen, picklable :class:`_Task`.

Inputs are checked here once (shapes, finite values, the forcing frequency); the options
were checked by the spec's constructor, so nothing below checks them again.
"""

from __future__ import annotations

import hashlib
import time
from dataclasses import dataclass, field, replace
from pathlib import Path
from types import ModuleType

import numpy as np

from ..contract import Contract, load_generated
from ..system import System
from .spec import RunResult, RunSpec

__all__ = ["BACKENDS", "Batch", "decide_backend", "integrate"]

BACKENDS = ("auto", "native", "numpy")


@dataclass(frozen=True, eq=False)
class Batch:
    """Many parameter points of one generated model, picklable for worker processes.

    Attributes
    ----------
    source : str
        Path of the generated module's file.
    digest : str
        sha256 of the file's bytes as this process read them; a worker loads exactly
        those bytes (``contract.load_generated``) or refuses.
    P : ndarray, shape (N, P)
        Parameter vectors in the module's order (``module.parameters(...)``).
    """

    source: str
    digest: str
    P: np.ndarray
    _module: ModuleType | None = field(default=None, repr=False)

    @classmethod
    def of(cls, module: ModuleType, P) -> Batch:
        """The batch of ``module`` (a generated module) at the rows of ``P``, shape (N, P)."""
        source = str(module.__file__)
        digest = hashlib.sha256(Path(source).read_bytes()).hexdigest()
        P = np.ascontiguousarray(np.atleast_2d(np.asarray(P, dtype=float)))
        return cls(source, digest, P, module)

    @property
    def module(self) -> ModuleType:
        """The generated module (loaded from the verified bytes in a worker)."""
        if self._module is None:
            data = Path(self.source).read_bytes()
            if hashlib.sha256(data).hexdigest() != self.digest:
                raise ValueError(f"{self.source} changed while a run was under way; run it again")
            object.__setattr__(self, "_module", load_generated(self.source, source=data))
        return self._module

    def __getitem__(self, rows) -> Batch:
        return Batch(self.source, self.digest, self.P[rows], self._module)

    def __getstate__(self) -> dict:
        # the module does not pickle: a worker loads it again from the verified file
        return {"source": self.source, "digest": self.digest, "P": self.P, "_module": None}


@dataclass(frozen=True, eq=False)
class _Task:
    """One worker's share: a slice of the batch, its initial states, the spec and the
    backend the parent decided."""

    batch: Batch
    X0: np.ndarray
    spec: RunSpec
    backend: str


def decide_backend(
    module: ModuleType, spec: RunSpec, backend: str = "auto", shared: tuple = ()
) -> str:
    """``"native"`` when the compiled library of ``module`` builds or is cached (with the
    variational system when the spec collects the exponent), else ``"numpy"`` after the
    one warning line (``backend="auto"``); ``"native"`` raises
    :class:`~.native.build.NativeUnavailable` instead, ``"numpy"`` is taken as given.
    ``shared``: the parameters equal across the batch the run takes (``library``'s), so
    that the library checked is the one the run uses (the library for any batch, built
    only to be checked, cost about a second of compiling per model and was never run)."""
    from .native.build import NativeUnavailable, library, monodromy_library
    from .native.fallback import fallback_warning

    if backend not in BACKENDS:
        raise ValueError(f"backend {backend!r} is unknown; backends: {', '.join(BACKENDS)}")
    if backend == "numpy":
        return backend
    kind = "exponent" in spec.collect
    if "monodromy" in spec.collect and monodromy_library(module):
        kind = "monodromy"  # (else a library compiled only to be checked)
    try:
        library(module, variational=kind, shared=shared)
    except NativeUnavailable as err:
        if backend == "native":
            raise
        fallback_warning(err)
        return "numpy"
    return "native"


def integrate(
    target: System | Batch,
    x0,
    spec: RunSpec,
    *,
    backend: str = "auto",
    workers: int = 1,
) -> RunResult:
    """Integrate one point or a batch of points as ``spec`` says.

    Parameters
    ----------
    target : System or Batch
        One parameter point (``N = 1``) or ``N`` points of one model.
    x0 : array_like, shape (n,) or (N, n)
        Initial states (one for every point, or one per point).
    spec : RunSpec
        The run's options, checked by its constructor.
    backend : {"auto", "native", "numpy"}
        The compiled engine, its fallback, or ``auto``: native when it builds (decided
        here once, one warning line otherwise).
    workers : int
        Processes to split the points over (``1``: this process).

    Returns
    -------
    RunResult
        Per point (in the order of ``target``'s rows): samples, extremes, exponent, work,
        status; ``label`` says which engine and method ran.
    """
    if not isinstance(spec, RunSpec):
        raise TypeError(f"spec must be a RunSpec, got {type(spec).__name__}")
    if isinstance(target, System):
        module, P, batch = target.module, target.p[None, :], None
    elif isinstance(target, Batch):
        module, P, batch = target.module, target.P, target
    else:
        raise TypeError(f"target must be a System or a Batch, got {type(target).__name__}")
    if isinstance(workers, bool) or not isinstance(workers, (int, np.integer)) or workers < 1:
        raise ValueError(f"workers must be a whole number >= 1, got {workers!r}")
    P = np.ascontiguousarray(np.asarray(P, dtype=float))
    X0 = _check_inputs(Contract.of(module), P, x0, spec)
    started = time.perf_counter()
    N = P.shape[0]
    chunks = [c for c in np.array_split(np.arange(N), min(workers, N)) if c.size]
    if backend != "numpy":
        from .native.engine import batch_shared

        # the libraries the shares of the batch run with
        for shared in dict.fromkeys(batch_shared(module, P[c], spec) for c in chunks):
            backend = decide_backend(module, spec, backend, shared)
    if workers > 1 and N > 1:
        from ..executor import map_tasks

        batch = batch or Batch.of(module, P)
        tasks = [_Task(batch[c], X0[c], spec, backend) for c in chunks]
        parts = map_tasks(_run_task, tasks, executor="processes", workers=len(chunks))
        return _join(parts, time.perf_counter() - started)
    return _run(module, P, X0, spec, backend)


def _check_inputs(contract: Contract, P: np.ndarray, x0, spec: RunSpec) -> np.ndarray:
    """``X0`` (N, n) from ``x0``, after checking ``P`` and ``x0`` once."""
    n, n_p = len(contract.states), len(contract.parameters)
    if P.ndim != 2 or P.shape[0] < 1 or P.shape[1] != n_p:
        raise ValueError(f"P must have shape (N, {n_p}) with N >= 1, got {P.shape}")
    N = P.shape[0]
    X0 = np.asarray(x0, dtype=float)
    if X0.shape == (n,):
        X0 = np.repeat(X0[None, :], N, axis=0)
    if X0.shape != (N, n):
        raise ValueError(f"x0 must have shape ({n},) or ({N}, {n}), got {X0.shape}")
    for name, a in (("P", P), ("x0", X0)):
        if not np.all(np.isfinite(a)):
            raise ValueError(
                f"{name} holds a NaN or infinite value; every parameter and initial "
                "state must be a finite number"
            )
    w_name = contract.forcing_frequency
    omega = P[:, contract.parameters.index(w_name)]
    if not np.all(omega > 0):
        raise ValueError(f"{w_name} (the forcing frequency) must be > 0 at every point")
    if spec.time == "tau" and np.ptp(omega) != 0.0:
        raise ValueError(
            f"{w_name} must be the same for every point in time 'tau'; give time='phase' "
            "to run several forcing frequencies together"
        )
    return np.ascontiguousarray(X0)


def _run_task(task: _Task) -> RunResult:
    return _run(task.batch.module, task.batch.P, task.X0, task.spec, task.backend)


def _run(module, P: np.ndarray, X0: np.ndarray, spec: RunSpec, backend: str) -> RunResult:
    if "monodromy" in spec.collect:
        return _monodromy(module, P, X0, spec, backend)
    return _engine(module, P, X0, spec, backend)


def _engine(module, P, X0, spec: RunSpec, backend: str, tangent0=None) -> RunResult:
    if backend == "numpy":
        from .native.fallback import run_fallback

        return run_fallback(module, P, X0, spec, tangent0)
    return _compiled(module, P, X0, spec, tangent0)


def _monodromy(module, P: np.ndarray, X0: np.ndarray, spec: RunSpec, backend: str) -> RunResult:
    """The monodromy of each point: by the monodromy library (:func:`_matrix_monodromy`,
    one run of the state and the matrix of tangents) where the model has its Jacobian in
    C and the engine is compiled; else each point run once per state, the tangent
    starting from that unit vector (the copies of a point side by side, so that a
    lock-step group mostly holds them together; copies in other groups differ by the
    steps only, about 1e-12): the monodromy's column k is the tangent's end times its
    growth.  The point's samples, extremes and exponent are then those of its first
    copy, or of its first copy that failed (which fails the point, its monodromy NaN)."""
    N, n = X0.shape
    inner = spec.with_(collect=tuple(c for c in spec.collect if c != "monodromy"))
    if backend != "numpy":
        from .native.build import NativeUnavailable, monodromy_library

        if monodromy_library(module):
            try:
                return _matrix_monodromy(module, P, X0, inner)
            except NativeUnavailable as err:  # the copies below, said once
                from .native.fallback import fallback_warning

                fallback_warning(err, "the monodromy's tangents as copies of the state instead")
    tangent0 = np.tile(np.eye(n), (N, 1))
    P, X0 = np.repeat(P, n, axis=0), np.repeat(X0, n, axis=0)
    res = _engine(module, P, X0, inner, backend, tangent0)
    ends = res.tangent.reshape(N, n, n + 1)
    M = (ends[:, :, :n] * np.exp(ends[:, :, n:])).transpose(0, 2, 1)
    # each point's first copy, or its first failed one (a failed copy fails the point)
    rows = np.arange(0, N * n, n)
    for i in range(N):
        failed = [k for k in range(i * n, (i + 1) * n) if res.status[k] != "ok"]
        if failed:
            rows[i] = failed[0]
            M[i] = np.nan

    def pick(a):
        return None if a is None else a[rows]

    return replace(
        res,
        x=pick(res.x),
        xmin=pick(res.xmin),
        xmax=pick(res.xmax),
        exponent=pick(res.exponent),
        exits=pick(res.exits),
        nfev=res.nfev.reshape(N, n).sum(axis=1),
        nsteps=res.nsteps.reshape(N, n).max(axis=1),
        status=tuple(res.status[k] for k in rows),
        t_fail=pick(res.t_fail),
        monodromy=M,
        tangent=None,
    )


def _matrix_monodromy(module, P: np.ndarray, X0: np.ndarray, spec: RunSpec) -> RunResult:
    """Each point run once with the matrix of tangents from the identity (the monodromy
    library, ``native/monodromy.c``): the monodromy is the matrix's end times its growth;
    a failed point's is NaN.  A piecewise force law's points take their own steps, as
    in :func:`_compiled`."""
    from .native.engine import run_compiled

    N, n = X0.shape
    # the identity scaled to unit norm: the engine rescales the tangent block at the start
    # too, without counting that growth
    W0 = np.tile(np.eye(n).ravel() / np.sqrt(n), (N, 1))
    piecewise = Contract.of(module).piecewise
    res = run_compiled(
        module, P, X0, spec.with_(group=1) if piecewise else spec, W0, monodromy=True
    )
    growth = np.sqrt(n) * np.exp(res.tangent[:, n * n :])[:, :, None]
    M = res.tangent[:, : n * n].reshape(N, n, n) * growth
    for i in range(N):
        if res.status[i] != "ok":
            M[i] = np.nan
    # the growth of the whole matrix is no exponent's estimate: none is given
    return replace(res, monodromy=M, tangent=None, exponent=None)


def _compiled(module, P: np.ndarray, X0: np.ndarray, spec: RunSpec, tangent0=None) -> RunResult:
    """The compiled engine (``native/engine.py``), with how points share steps: a
    piecewise force law (the dead zone) would shrink a whole group's step at each point's
    kinks, so its sampled runs go point by point and its maps in groups of one; RK4 and a
    single point always take their own steps."""
    from .native.engine import run_compiled

    piecewise = Contract.of(module).piecewise
    if "extremes" in spec.collect or "exponent" in spec.collect:
        return run_compiled(module, P, X0, spec.with_(group=1) if piecewise else spec, tangent0)
    if spec.time == "phase":
        return run_compiled(module, P, X0, spec)
    lockstep = spec.lockstep and not piecewise and spec.method != "rk4" and P.shape[0] > 1
    return run_compiled(module, P, X0, spec.with_(lockstep=lockstep))


def _join(parts: list[RunResult], wall_time: float) -> RunResult:
    """One result from the workers' parts, in task order."""

    def cat(name):
        first = getattr(parts[0], name)
        return None if first is None else np.concatenate([getattr(r, name) for r in parts])

    return RunResult(
        t=parts[0].t,
        x=cat("x"),
        nfev=cat("nfev"),
        nsteps=cat("nsteps"),
        status=tuple(s for r in parts for s in r.status),
        t_fail=cat("t_fail"),
        method=parts[0].method,
        backend=parts[0].backend,
        xmin=cat("xmin"),
        xmax=cat("xmax"),
        exponent=cat("exponent"),
        exits=cat("exits"),
        monodromy=cat("monodromy"),
        wall_time=wall_time,
        compile_seconds=max(r.compile_seconds for r in parts),
    )
