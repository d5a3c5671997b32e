"""Compiled batched integration: the generated C right-hand side driven by C integrators.

``run_batch(module, P, X0, ...)`` integrates many parameter points of one generated model
in one call of native code: Dormand-Prince 5(4) (``dopri5``), DOP853 (``dop853``) or
classic RK4 (``rk4``), the step control of SciPy's RK45/DOP853, sampled ``spp`` times per
forcing period after a transient (``solver/_native.c``).

Route: the generated module carries its right-hand side as C (``C_SOURCE``, printed by
``derive/emit_c.py`` from the same SymPy expressions as the NumPy and CasADi code, with the
excitation's harmonics reduced to one ``sincos`` per step stage).  It is compiled with the
system C compiler (``cc``, or ``$GEARSYM_CC``) together with the integrators into a shared
library, loaded with ``ctypes`` and cached on disk under ``$GEARSYM_CACHE`` (default
``~/.cache/gearsym``) keyed by the sha256 of its full source and the compiler, so that a
second run pays no compile time.  Without a working compiler everything still runs
through NumPy/SciPy (one vectorised system under SciPy's RK45/DOP853, or NumPy RK4), with a
warning.
"""

from __future__ import annotations

import ctypes
import functools
import hashlib
import os
import platform
import shutil
import subprocess
import tempfile
import time
import warnings
from dataclasses import dataclass
from pathlib import Path

import numpy as np

__all__ = [
    "NATIVE_METHODS",
    "benettin",
    "BatchResult",
    "NativeUnavailable",
    "compiler",
    "library",
    "run_batch",
]

NATIVE_METHODS = ("dopri5", "dop853", "rk4")
_CODES = {"dopri5": 0, "dop853": 1, "rk4": 2}
STATUS = {0: "ok", 1: "divergent", 2: "too many steps", 3: "not finite", 4: "step too small"}
_FLAGS = (
    "-O3",
    "-march=native",
    "-fno-math-errno",
    "-fPIC",
    "-shared",
    "-Werror=implicit-function-declaration",
)
_loaded: dict[str, ctypes.CDLL] = {}
_warned: set[str] = set()
_paths: dict[tuple, Path] = {}  # (module file, inputs hash, variational, compiler) -> library
_failed: dict[str, str] = {}  # cache key -> why it could not be built (once per session)


class NativeUnavailable(RuntimeError):
    """No C compiler, or the compilation failed: the NumPy path is used instead."""


def compiler() -> str | None:
    """The C compiler to use: ``$GEARSYM_CC`` if set (``none`` disables), else cc/gcc/clang."""
    env = os.environ.get("GEARSYM_CC")
    if env is not None:
        if env.strip().lower() in ("", "none", "0"):
            return None
        return shutil.which(env) or (env if Path(env).exists() else None)
    for name in ("cc", "gcc", "clang"):
        found = shutil.which(name)
        if found:
            return found
    return None


def cache_dir() -> Path:
    env = os.environ.get("GEARSYM_CACHE")
    if env:
        return Path(env)
    base = os.environ.get("XDG_CACHE_HOME") or (Path.home() / ".cache")
    return Path(base) / "gearsym"


def _tables() -> str:
    """Butcher tables as C arrays, from SciPy's own coefficients (no transcription)."""
    from scipy.integrate._ivp import dop853_coefficients as d
    from scipy.integrate._ivp.rk import RK45

    def arr(name, values):
        flat = np.asarray(values, dtype=float).ravel()
        body = ", ".join(repr(float(v)) for v in flat)
        return f"static const double {name}[{flat.size}] = {{{body}}};"

    n = d.N_STAGES
    return "\n".join(
        [
            arr("GS_RK45_A", np.pad(RK45.A, ((0, 0), (0, RK45.n_stages - RK45.A.shape[1])))),
            arr("GS_RK45_B", RK45.B),
            arr("GS_RK45_C", RK45.C),
            arr("GS_RK45_E", RK45.E),
            arr("GS_DOP853_A", d.A[:n, :n]),
            arr("GS_DOP853_B", d.B),
            arr("GS_DOP853_C", d.C[:n]),
            arr("GS_DOP853_E3", d.E3),
            arr("GS_DOP853_E5", d.E5),
        ]
    )


def source(module, variational: bool = False) -> str:
    """Full C text of the library for a generated module (``variational``: the state
    extended by a tangent vector, with ``gs_benettin``)."""
    attr = "C_SOURCE_VARIATIONAL" if variational else "C_SOURCE"
    if not hasattr(module, attr):
        raise NativeUnavailable(
            f"generated module '{module.NAME}' has no {attr}; regenerate it with `gearsym derive`"
        )
    body = (Path(__file__).with_name("_native.c")).read_text(encoding="utf-8")
    head = ["#define GS_VARIATIONAL 1"] if variational else []
    return "\n".join([*head, "#include <math.h>", getattr(module, attr), _tables(), body])


@functools.lru_cache(maxsize=8)
def _compiler_id(cc: str) -> str:
    """The compiler's version line and this CPU's identity: the libraries are built with
    -march=native, so a cache shared between machines (a cluster's home) keeps one per CPU."""
    try:
        out = subprocess.run([cc, "--version"], capture_output=True, text=True, timeout=30)
        version = out.stdout.splitlines()[0] if out.stdout else cc
    except (OSError, subprocess.SubprocessError):
        version = cc
    cpu = platform.machine()
    try:
        with open("/proc/cpuinfo", encoding="utf-8", errors="replace") as fh:
            for line in fh:
                if line.startswith(("flags", "Features", "model name")):
                    cpu += "|" + line.strip()
    except OSError:
        cpu += "|" + platform.processor()
    return version + "|" + cpu


def library(module, variational: bool = False) -> tuple[ctypes.CDLL, dict]:
    """Compile (or load from the cache) the native library of ``module``.

    Returns the library and facts: ``path``, ``compiled`` (bool: built now), ``seconds``.
    Raises :class:`NativeUnavailable` without a working compiler.
    """
    cc = compiler()
    if cc is None:
        raise NativeUnavailable("no C compiler found (install gcc or clang, or set GEARSYM_CC)")
    memo = (getattr(module, "__file__", module.NAME), getattr(module, "INPUTS_SHA256", ""),
            variational, cc, str(cache_dir()))  # fmt: skip
    facts = {"compiled": False, "seconds": 0.0, "compiler": cc}
    path = _paths.get(memo)
    if path is not None and str(path) in _loaded:
        facts["path"] = str(path)
        return _loaded[str(path)], facts
    text = source(module, variational)
    key = hashlib.sha256(
        "\n".join([text, _compiler_id(cc), " ".join(_FLAGS)]).encode()
    ).hexdigest()[:20]
    if key in _failed:
        raise NativeUnavailable(_failed[key])
    path = cache_dir() / f"{module.NAME}{'-var' if variational else ''}-{key}.so"
    facts["path"] = str(path)
    if str(path) in _loaded:
        _paths[memo] = path
        return _loaded[str(path)], facts
    if not path.exists():
        started = time.perf_counter()
        path.parent.mkdir(parents=True, exist_ok=True)
        with tempfile.TemporaryDirectory(dir=path.parent) as tmp:
            c_file = Path(tmp) / "model.c"
            c_file.write_text(text, encoding="utf-8")
            so = Path(tmp) / "lib.so"
            try:
                done = subprocess.run(
                    [cc, *_FLAGS, "-o", str(so), str(c_file), "-lm"],
                    capture_output=True,
                    text=True,
                    timeout=300,
                )
            except (OSError, subprocess.SubprocessError) as err:
                _failed[key] = f"the C compiler {cc} could not be run: {err}"
                raise NativeUnavailable(_failed[key]) from None
            if done.returncode != 0:
                first = (done.stderr or done.stdout).strip().splitlines()[:3]
                _failed[key] = f"compiling {module.NAME} failed: {' / '.join(first)}"
                raise NativeUnavailable(_failed[key])
            os.replace(so, path)  # atomic: parallel workers never see half a library
        facts.update(compiled=True, seconds=time.perf_counter() - started)
    _paths[memo] = path
    lib = ctypes.CDLL(str(path))
    d, i, ll = ctypes.c_double, ctypes.c_int, ctypes.c_longlong
    ptr = np.ctypeslib.ndpointer
    lib.gs_run.restype = i
    lib.gs_run.argtypes = [
        i, i,
        ptr(np.float64, flags="C"), ptr(np.float64, flags="C"),
        d, d, i, i, i, d, d, i, d, ll,
        ptr(np.float64, flags="C"), ptr(np.int64, flags="C"), ptr(np.int64, flags="C"),
        ptr(np.int32, flags="C"), ptr(np.float64, flags="C"),
    ]  # fmt: skip
    lib.gs_run_lockstep.restype = i
    lib.gs_run_lockstep.argtypes = [
        i, i, i,
        ptr(np.float64, flags="C"), ptr(np.float64, flags="C"),
        d, d, i, i, i, d, d, d, ll,
        ptr(np.float64, flags="C"), ptr(np.int64, flags="C"), ptr(np.int64, flags="C"),
        ptr(np.int32, flags="C"), ptr(np.float64, flags="C"),
    ]  # fmt: skip
    lib.gs_eval.restype = None
    lib.gs_eval.argtypes = [d, ptr(np.float64, flags="C"), ptr(np.float64, flags="C"),
                            ptr(np.float64, flags="C")]  # fmt: skip
    lib.gs_eval_batch.restype = None
    lib.gs_eval_batch.argtypes = [d, i, ptr(np.float64, flags="C"), ptr(np.float64, flags="C"),
                                  ptr(np.float64, flags="C")]  # fmt: skip
    lib.gs_rhs_loop.restype = d
    lib.gs_rhs_loop.argtypes = [ptr(np.float64, flags="C"), ptr(np.float64, flags="C"), ll, d]
    if variational:
        lib.gs_benettin.restype = i
        lib.gs_benettin.argtypes = [
            ptr(np.float64, flags="C"), ptr(np.float64, flags="C"), d, d, i, d, d, d, ll,
            ptr(np.float64, flags="C"), ptr(np.int64, flags="C"),
        ]  # fmt: skip
    _loaded[str(path)] = lib
    return lib, facts


@dataclass(frozen=True)
class BatchResult:
    """Samples of many points: ``x`` (N, K, n) at ``t`` (K,), with per-point work and status."""

    t: np.ndarray
    x: np.ndarray
    nfev: np.ndarray
    nsteps: np.ndarray
    status: tuple[str, ...]
    t_fail: np.ndarray
    backend: str  # "native" or "numpy"
    wall_time: float
    compile_seconds: float = 0.0


def run_batch(
    module,
    P,
    X0,
    *,
    method: str = "dop853",
    rtol: float = 1e-8,
    atol: float = 1e-10,
    t0: float = 0.0,
    transient: int = 300,
    periods: int = 100,
    samples_per_period: int = 1,
    steps_per_period: int = 256,
    bound: float = 1e3,
    max_steps: int = 50_000_000,
    lockstep: bool = True,
    group: int = 64,
    workers: int = 1,
    fallback: bool = True,
) -> BatchResult:
    """Integrate every column set ``P[i]`` (parameters) from ``X0[i]`` of ``module``.

    ``P``: (N, P) parameter vectors (``module.parameters(...)``); ``X0``: (N, n).  The
    excitation period is ``2 pi / omega`` with ``omega = P[:, 0]`` (the same for all points).
    Samples: ``t0 + (transient + k / samples_per_period) T`` for
    ``k = 0 .. periods * samples_per_period`` (the last one closes the window).

    ``lockstep``: groups of ``group`` points share time and step size (the excitation is
    computed once per stage for the group and the arithmetic vectorises); otherwise each
    point takes its own steps.  RK4 always runs point by point.
    """
    if method not in NATIVE_METHODS:
        raise ValueError(f"unknown native method '{method}'; methods: {', '.join(NATIVE_METHODS)}")
    P = np.ascontiguousarray(np.atleast_2d(np.asarray(P, dtype=float)))
    X0 = np.ascontiguousarray(np.atleast_2d(np.asarray(X0, dtype=float)))
    n = len(module.STATES)
    if P.shape[1] != len(module.PARAMETERS) or X0.shape != (P.shape[0], n):
        raise ValueError(
            f"P must be (N, {len(module.PARAMETERS)}) and X0 (N, {n}); got {P.shape} and {X0.shape}"
        )
    if not (np.all(np.isfinite(P)) and np.all(np.isfinite(X0))):
        bad = "P" if not np.all(np.isfinite(P)) else "X0"
        raise ValueError(f"{bad} holds a NaN or infinite value; every parameter and initial "
                         "state must be a finite number")  # fmt: skip
    omega = P[:, 0]
    if not (np.all(np.isfinite(omega)) and np.all(omega > 0)) or np.ptp(omega) != 0.0:
        raise ValueError("omega (P[:, 0]) must be positive and the same for every point")
    if not (rtol > 0 and atol > 0):
        raise ValueError(f"tolerances must be > 0, got rtol={rtol}, atol={atol}")
    spp = int(samples_per_period)
    if method == "rk4" and (steps_per_period < spp or steps_per_period % spp):
        raise ValueError(
            f"steps_per_period ({steps_per_period}) must be a multiple of samples_per_period "
            f"({spp}) for rk4"
        )
    period = 2.0 * np.pi / float(omega[0])
    k = periods * spp + 1
    t = t0 + (transient + np.arange(k) / spp) * period
    started = time.perf_counter()
    if "?" in getattr(module, "C_SOURCE", ""):
        # A piecewise force law (the dead zone): each point's kinks would shrink the step
        # of the whole group, so such models run point by point.
        lockstep = False
    if workers > 1 and P.shape[0] > 1:
        return _parallel(module, P, X0, workers, started, dict(
            method=method, rtol=rtol, atol=atol, t0=t0, transient=transient, periods=periods,
            samples_per_period=spp, steps_per_period=steps_per_period, bound=bound,
            max_steps=max_steps, lockstep=lockstep, group=group, fallback=fallback))  # fmt: skip
    try:
        lib, facts = library(module)
    except NativeUnavailable as err:
        if not fallback:
            raise
        if str(err) not in _warned:
            _warned.add(str(err))
            warnings.warn(f"{err}; integrating with NumPy instead (slower)", stacklevel=2)
        return _numpy_batch(module, P, X0, method, rtol, atol, t0, transient, periods, spp,
                            steps_per_period, bound, t, started)  # fmt: skip
    N = P.shape[0]
    out = np.empty((N, k, n))
    nfev = np.zeros(N, dtype=np.int64)
    nsteps = np.zeros(N, dtype=np.int64)
    status = np.zeros(N, dtype=np.int32)
    t_fail = np.zeros(N)
    if lockstep and method != "rk4" and N > 1:
        code = lib.gs_run_lockstep(_CODES[method], N, int(group), P, X0, float(t0), period,
                                   int(transient), int(periods), spp, float(rtol), float(atol),
                                   float(bound), int(max_steps), out, nfev, nsteps, status,
                                   t_fail)  # fmt: skip
        if code != 0:
            raise MemoryError("the lockstep integrator could not allocate its work arrays")
    else:
        lib.gs_run(_CODES[method], N, P, X0, float(t0), period, int(transient), int(periods),
                   spp, float(rtol), float(atol), int(steps_per_period), float(bound),
                   int(max_steps), out, nfev, nsteps, status, t_fail)  # fmt: skip
    return BatchResult(
        t=t,
        x=out,
        nfev=nfev,
        nsteps=nsteps,
        status=tuple(STATUS[int(s)] for s in status),
        t_fail=t_fail,
        backend="native",
        wall_time=time.perf_counter() - started,
        compile_seconds=facts["seconds"],
    )


def _chunk(args):
    source, P, X0, kwargs = args
    from ._models import load_generated

    return run_batch(load_generated(source), P, X0, **kwargs)


def _parallel(module, P, X0, workers, started, kwargs) -> BatchResult:
    """Split the points into ``workers`` contiguous chunks run by as many processes."""
    from concurrent.futures import ProcessPoolExecutor

    source = module.__file__
    try:
        library(module)  # compile once here, not in every worker
    except NativeUnavailable:
        if not kwargs.get("fallback", True):
            raise
        return run_batch(module, P, X0, **kwargs)  # the NumPy path, in this process
    chunks = [c for c in np.array_split(np.arange(P.shape[0]), workers) if c.size]
    with ProcessPoolExecutor(max_workers=len(chunks)) as pool:
        parts = list(pool.map(_chunk, [(source, P[c], X0[c], kwargs) for c in chunks]))
    return BatchResult(
        t=parts[0].t,
        x=np.concatenate([r.x for r in parts]),
        nfev=np.concatenate([r.nfev for r in parts]),
        nsteps=np.concatenate([r.nsteps for r in parts]),
        status=tuple(s for r in parts for s in r.status),
        t_fail=np.concatenate([r.t_fail for r in parts]),
        backend=parts[0].backend,
        wall_time=time.perf_counter() - started,
    )


def _numpy_batch(module, P, X0, method, rtol, atol, t0, transient, periods, spp,
                 steps_per_period, bound, t, started) -> BatchResult:  # fmt: skip
    """The same integration without a compiler: SciPy's RK45/DOP853 point by point on the
    generated NumPy right-hand side (each with an escape event at ``bound``), or NumPy RK4
    on all points at once, on the same grid as the C code."""
    from scipy.integrate import solve_ivp

    N, n = X0.shape
    Pt = P.T.copy()
    period = 2.0 * np.pi / float(P[0, 0])
    if method == "rk4":
        h = period / steps_per_period
        y = X0.T.copy()
        out = np.empty((N, len(t), n))
        steps_total = (transient + periods) * steps_per_period
        stride = steps_per_period // spp
        first = transient * steps_per_period
        for j in range(steps_total + 1):
            if j >= first and (j - first) % stride == 0:
                out[:, (j - first) // stride, :] = y.T
            if j == steps_total:
                break
            tj = t0 + j * h
            k1 = module.rhs(tj, y, Pt)
            k2 = module.rhs(tj + h / 2, y + h / 2 * k1, Pt)
            k3 = module.rhs(tj + h / 2, y + h / 2 * k2, Pt)
            k4 = module.rhs(tj + h, y + h * k3, Pt)
            y = y + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
        nfev = np.full(N, 4 * steps_total)
        nsteps = np.full(N, steps_total)
        finite = np.all(np.isfinite(out), axis=(1, 2))
        big = np.any(np.abs(np.nan_to_num(out)) > bound, axis=(1, 2))
        status = tuple("ok" if f and not b else ("divergent" if b else "not finite")
                       for f, b in zip(finite, big, strict=True))  # fmt: skip
        t_fail = np.full(N, np.nan)
    else:
        # point by point, each stopped by its own escape event (a diverging point must not
        # hold up the others, as one stacked system would)
        out = np.full((N, len(t), n), np.nan)
        nfev = np.zeros(N, dtype=np.int64)
        nsteps = np.zeros(N, dtype=np.int64)
        status, t_fail = [], np.full(N, np.nan)

        def escape(tt, yy):
            return bound - np.max(np.abs(yy))

        escape.terminal = True
        for i in range(N):
            sol = solve_ivp(lambda tt, yy, pp=P[i]: module.rhs(tt, yy, pp), (t0, t[-1]), X0[i],
                            method="RK45" if method == "dopri5" else "DOP853", t_eval=t,
                            rtol=rtol, atol=atol, events=escape)  # fmt: skip
            ys = np.asarray(sol.y, dtype=float).reshape(n, -1)  # [] when no sample was reached
            out[i, : ys.shape[1], :] = ys.T
            nfev[i], nsteps[i] = sol.nfev, len(sol.t)
            if sol.status == 1:
                status.append("divergent")
                t_fail[i] = float(sol.t_events[0][0])
            elif sol.status != 0 or not np.all(np.isfinite(ys)):
                status.append("not finite")
                t_fail[i] = float(sol.t[-1]) if sol.t.size else t0
            else:
                status.append("ok")
        status = tuple(status)
    return BatchResult(
        t=t,
        x=out,
        nfev=nfev,
        nsteps=nsteps,
        status=status,
        t_fail=t_fail,
        backend="numpy",
        wall_time=time.perf_counter() - started,
    )


def benettin(module, p, z0, *, t0: float, periods: int, rtol: float, atol: float):
    """Running estimate of the largest Lyapunov exponent (``solver/lyapunov.py``) in native
    code: DOP853 on the variational equations, renormalised every period.  Returns
    ``(running, nfev)``; raises :class:`NativeUnavailable` without a compiler and
    ``FloatingPointError`` when the run fails."""
    lib, _ = library(module, variational=True)
    p = np.ascontiguousarray(p, dtype=float)
    z0 = np.ascontiguousarray(z0, dtype=float)
    running = np.empty(periods)
    nfev = np.zeros(1, dtype=np.int64)
    period = 2.0 * np.pi / float(p[0])
    status = lib.gs_benettin(p, z0, float(t0), period, int(periods), float(rtol), float(atol),
                             1e12, 50_000_000, running, nfev)  # fmt: skip
    if status != 0:
        raise FloatingPointError(f"variational integration stopped: {STATUS[status]}")
    return running, int(nfev[0])
