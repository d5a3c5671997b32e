"""Speed and accuracy of every integration back end: writes performance.md and its figure.

Run: ``gearsym bench [--quick] [--json] [--out DIR | --docs]``, or the same options to
``python -m gearsym.benchmarks.performance`` (from a checkout also
``python benchmarks/performance.py``). The report ``performance.md`` and the figure
``performance-pareto.png`` go to ``--out DIR`` (default ``bench-out``, created if missing)
or, with ``--docs``, to the checkout's ``docs/`` (the tracked report). The folder is
checked for writing before the benchmark starts.

Sections (every timing a median of repeated runs on this machine, ratios measured in the
same run):

1. Headline: the light-load reference sweep over the load ratio (400 points, 300 transient
   + 100 sampled periods, rtol 1e-8) with the compiled batched DOP853, against the plain
   baseline a user would write (``solve_ivp(RK45)`` with a hand-written Python right-hand
   side; timed on a subset of the points and scaled to 400) and against the hand-written
   vectorised lockstep DOP853 in C of ``benchmarks/lockstep_reference.c``.
2. Throughput: right-hand-side evaluations per second of one-point-at-a-time integration.
3. Pareto: error of the Poincare points against a tight reference, time per point and
   evaluations, for every back end and tolerances 1e-3 ... 1e-12 (fixed-step methods: steps
   per period).
4. Feature cost: time and modelling error of each model feature.
5. Scaling with the sweep size and with the number of meshes; compile times.
6. Appended sections (:data:`SECTIONS`): the user-facing ``gearsym sweep`` of 400
   independent points as a user runs it (a new process each time, start-up included)
   against the baseline of section 1 measured in the same run; the 50 x 50 regime map
   (``benchmarks/atlas.py``); a table of the speed floors of issue 12 side by side.
"""

from __future__ import annotations

import argparse
import ctypes
import json
import math
import os
import statistics
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np

# absolute, so that ``python benchmarks/performance.py`` runs too
from gearsym.benchmarks._output import OutputError, checkout_docs, output_folder, run_script

REPORT = "performance.md"
FIGURE = "performance-pareto.png"
DEFAULT_OUT = "bench-out"


def _median_time(fn, repeats: int, long: float = 2.0):
    """Median wall time of ``repeats`` runs (a single run when it takes over ``long`` s)."""
    times, out = [], None
    for _ in range(repeats):
        started = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - started)
        if times[0] > long:
            break
    return statistics.median(times), out


# ---------------------------------------------------------------- the reference model
def _reference(lam=None):
    from gearsym.solver.integrate import default_initial_state
    from gearsym.solver.system import System

    system = System.load("reference_light")
    module = system.module
    lam = np.linspace(0.0, 1.0, 400) if lam is None else np.asarray(lam, float)
    P = np.array([module.parameters(**{"lambda": v}) for v in lam])
    X0 = np.repeat(default_initial_state(system)[None, :], len(lam), axis=0)
    return module, lam, P, X0


def _named(module, p) -> dict:
    return dict(zip(module.PARAMETERS, p, strict=True))


def plain_rhs(q: dict):
    """The right-hand side a user would write by hand: plain Python and the math module."""
    cos, sin = math.cos, math.sin
    w, phi = q["omega"], q["phi_v"]
    a_u = (q["kc_u_1"], q["kc_u_2"], q["kc_u_3"])
    b_u = (q["ks_u_1"], q["ks_u_2"], q["ks_u_3"])
    a_v = (q["kc_v_1"], q["kc_v_2"], q["kc_v_3"])
    b_v = (q["ks_v_1"], q["ks_v_2"], q["ks_v_3"])
    g1, g3, g5, g7 = q["g1"], q["g3"], q["g5"], q["g7"]

    def g(x):
        return g1 * x + g3 * x**3 + g5 * x**5 + g7 * x**7

    def f(t, y):
        u, v, du, dv = y
        ku, kv = 1.0, 1.0
        for h in (1, 2, 3):
            ku += a_u[h - 1] * cos(h * w * t) + b_u[h - 1] * sin(h * w * t)
            kv += a_v[h - 1] * cos(h * (w * t - phi)) + b_v[h - 1] * sin(h * (w * t - phi))
        eu = -q["E_u_1"] * w**2 * cos(w * t + q["psi_u_1"])
        ev = -q["E_v_1"] * w**2 * cos(w * t - phi + q["psi_v_1"])
        gu, gv = ku * g(u), kv * g(v)
        ddu = (
            q["f_u"]
            + eu
            - 2 * (q["xi_u_u"] * du + q["xi_u_v"] * dv)
            - q["kappa_u_u"] * gu
            - q["kappa_u_v"] * gv
        )
        ddv = (
            q["f_v"]
            + ev
            - 2 * (q["xi_v_u"] * du + q["xi_v_v"] * dv)
            - q["kappa_v_u"] * gu
            - q["kappa_v_v"] * gv
        )
        return [du, dv, ddu, ddv]

    return f


def baseline_point(module, p, x0, transient, periods, rtol=1e-8, atol=1e-10, method="RK45"):
    from scipy.integrate import solve_ivp

    contract = module.CONTRACT
    T = 2 * math.pi / p[contract["parameters"].index(contract["forcing_frequency"])]
    t_eval = (transient + np.arange(periods + 1)) * T
    sol = solve_ivp(
        plain_rhs(_named(module, p)),
        (0.0, t_eval[-1]),
        x0,
        method=method,
        t_eval=t_eval,
        rtol=rtol,
        atol=atol,
    )
    return sol.y.T, sol.nfev


def _reference_library():
    """Compile lockstep_reference.c, shipped beside this module (cached like the models)."""
    from gearsym.solver.integrate import native

    cc = native.compiler()
    if cc is None:
        return None
    src = Path(__file__).resolve().parent / "lockstep_reference.c"
    out = native.cache_dir() / "lockstep_reference.so"
    if not out.exists() or out.stat().st_mtime < src.stat().st_mtime:
        out.parent.mkdir(parents=True, exist_ok=True)
        flags = "-O3 -march=native -fno-math-errno -fPIC -shared".split()
        subprocess.run([cc, *flags, "-o", str(out), str(src), "-lm"], check=True)
    lib = ctypes.CDLL(str(out))
    ptr = np.ctypeslib.ndpointer(np.float64, flags="C")
    lib.ref_run.restype = ctypes.c_longlong
    # ref_run(n, fu, fv, consts, A, B, C, E3, E5, x0, transient, periods, rtol, atol, out)
    c_int, c_double = ctypes.c_int, ctypes.c_double
    lib.ref_run.argtypes = [c_int, *[ptr] * 9, c_int, c_int, c_double, c_double, ptr]
    return lib


def reference_run(lib, module, P, X0, transient, periods, rtol=1e-8, atol=1e-10):
    from scipy.integrate._ivp import dop853_coefficients as d

    q = _named(module, P[0])
    # the order of the constants array in lockstep_reference.c
    names = (
        "omega xi_u_u xi_u_v xi_v_u xi_v_v kappa_u_u kappa_u_v kappa_v_u kappa_v_v "
        "kc_u_1 kc_u_2 kc_u_3 ks_u_1 ks_u_2 ks_u_3 kc_v_1 kc_v_2 kc_v_3 ks_v_1 ks_v_2 ks_v_3 "
        "phi_v E_u_1 psi_u_1 E_v_1 psi_v_1 g1 g3 g5 g7"
    ).split()
    consts = np.array([q[k] for k in names])
    n = len(P)
    fu = np.ascontiguousarray(P[:, module.PARAMETERS.index("f_u")])
    fv = np.ascontiguousarray(P[:, module.PARAMETERS.index("f_v")])
    out = np.empty((n, periods + 1, 4))
    c = np.ascontiguousarray
    nfev = lib.ref_run(
        n,
        fu,
        fv,
        consts,
        c(d.A[:12, :12]),
        c(d.B),
        c(d.C[:12]),
        c(d.E3),
        c(d.E5),
        c(X0),
        transient,
        periods,
        rtol,
        atol,
        out,
    )
    return out, nfev


# ---------------------------------------------------------------- 1. headline
def headline(quick: bool) -> dict:
    from gearsym.solver.integrate.native import run_batch

    module, lam, P, X0 = _reference()
    tr, per = 300, 100
    reps = 3
    # independent reference for the accuracy comparison: CVODES (BDF) at rtol 1e-13
    subset = np.linspace(0, len(lam) - 1, 2 if quick else 6).round().astype(int)
    from gearsym.solver.integrate import simulate
    from gearsym.solver.system import System

    tight = []
    for i in subset:
        s = System(module, P[i])
        tight.append(
            simulate(
                s,
                X0[i],
                method="cvodes",
                rtol=1e-13,
                atol=1e-15,
                transient=tr,
                periods=per,
                samples_per_period=1,
            ).x.T
        )
    tight = np.array(tight)
    baselines = {}
    for method in ("RK45", "DOP853"):
        times, errs, nfevs = [], [], []
        for k, i in enumerate(subset):
            t_i, (y, nfev) = _median_time(
                lambda i=i, method=method: baseline_point(
                    module, P[i], X0[i], tr, per, method=method
                ),
                1 if quick else 2,
            )
            times.append(t_i)
            nfevs.append(nfev)
            errs.append(float(np.max(np.abs(y[:-1] - tight[k]))))
        baselines[method] = (statistics.median(times), max(errs), float(statistics.median(nfevs)))
    run_batch(module, P[:2], X0[:2], transient=1, periods=1)  # compile outside the timing
    t_one, res_one = _median_time(
        lambda: run_batch(module, P, X0, method="dop853", transient=tr, periods=per), reps
    )
    t_two, res_two = _median_time(
        lambda: run_batch(module, P, X0, method="dop853", transient=tr, periods=per, workers=2),
        reps,
    )
    ours_err = float(np.max(np.abs(res_one.x[subset, :-1] - tight)))
    lib = _reference_library()
    if lib is not None:
        t_ref, (ref_x, ref_nfev) = _median_time(
            lambda: reference_run(lib, module, P, X0, tr, per), reps
        )
        ref_err = float(np.max(np.abs(ref_x[subset, :-1] - tight)))
    else:
        t_ref, ref_nfev, ref_err = float("nan"), 0, float("nan")
    per_point, base_err, base_nfev = baselines["RK45"]
    per_point_853, base_err_853, base_nfev_853 = baselines["DOP853"]
    baseline_400 = per_point * len(lam)
    return {
        "points": len(lam),
        "transient_periods": tr,
        "sampled_periods": per,
        "rtol": 1e-8,
        "baseline_points_timed": len(subset),
        "baseline_s_per_point": per_point,
        "baseline_s_400": baseline_400,
        "baseline_nfev_per_point": base_nfev,
        "baseline_max_poincare_error": base_err,
        "baseline_dop853_s_400": per_point_853 * len(lam),
        "baseline_dop853_nfev_per_point": base_nfev_853,
        "baseline_dop853_max_poincare_error": base_err_853,
        "compiled_1_core_s": t_one,
        "compiled_2_cores_s": t_two,
        "compiled_nfev_per_point": float(np.median(res_one.nfev)),
        "compiled_max_poincare_error": ours_err,
        "reference_c_s": t_ref,
        "reference_c_nfev_per_point": float(ref_nfev),
        "reference_c_max_poincare_error": ref_err,
        "speedup_1_core": baseline_400 / t_one,
        "speedup_2_cores": baseline_400 / t_two,
        "speedup_1_core_vs_dop853_baseline": per_point_853 * len(lam) / t_one,
        "over_reference_1_core": t_one / t_ref,
        "accuracy_reference": "CVODES (BDF) at rtol 1e-13 on the timed baseline points",
    }


# ---------------------------------------------------------------- 2. throughput
def throughput(quick: bool) -> dict:
    from gearsym.solver.integrate.native import library, run_batch

    module, lam, P, X0 = _reference(np.linspace(0.6, 1.0, 20))
    lib, _ = library(module)
    n = 20_000_000 if not quick else 5_000_000
    t_loop, _ = _median_time(lambda: lib.gs_rhs_loop(P[0], X0[0], n, 1e-3), 3)
    t_int, res = _median_time(
        lambda: run_batch(
            module, P, X0, method="dop853", transient=300, periods=100, lockstep=False
        ),
        3,
    )
    return {
        "rhs_only_evals_per_s": n / t_loop,
        "one_point_dop853_evals_per_s": float(res.nfev.sum()) / t_int,
        "one_point_dop853_ms_per_point": 1e3 * t_int / len(lam),
    }


# ---------------------------------------------------------------- 3. Pareto
ADAPTIVE = ["RK45", "DOP853", "LSODA", "Radau", "cvodes", "dopri5", "dop853"]
FIXED = ["rk", "collocation", "rk4"]


def pareto(quick: bool) -> list[dict]:
    from gearsym.solver.integrate import simulate
    from gearsym.solver.system import System

    module, lam, P, X0 = _reference(np.linspace(0.1, 0.9, 2 if quick else 4))
    tr, per = (10, 5) if quick else (20, 10)
    tols = [1e-3, 1e-6, 1e-9] if quick else [10.0**-k for k in range(3, 13)]
    steps = [32, 128] if quick else [16, 32, 64, 128, 256, 512, 1024]
    # reference: Radau IIA (implicit, an independent method) at rtol 1e-12; over this window
    # it agrees with SciPy's DOP853 at rtol 1e-13 to about 1e-13
    refs = [
        simulate(
            System(module, p),
            x0,
            method="Radau",
            rtol=1e-12,
            atol=1e-14,
            transient=tr,
            periods=per,
            samples_per_period=1,
        ).x
        for p, x0 in zip(P, X0, strict=True)
    ]
    rows = []

    def measure(method, **kw):
        errs, times, nfev = [], [], []
        for p, x0, ref in zip(P, X0, refs, strict=True):
            s = System(module, p)
            t, r = _median_time(
                lambda s=s, x0=x0: simulate(
                    s, x0, method=method, transient=tr, periods=per, samples_per_period=1, **kw
                ),
                1 if quick else 3,
            )
            errs.append(float(np.max(np.abs(r.x - ref))) if r.status == "ok" else float("inf"))
            times.append(t)
            nfev.append(r.nfev)
        return max(errs), statistics.median(times), statistics.median(nfev)

    slow = 5.0  # s per point: tighter settings of a method this slow are not run
    for method in ADAPTIVE:
        for tol in tols:
            err, t, nfev = measure(method, rtol=tol, atol=tol * 1e-2)
            rows.append(
                {
                    "method": method,
                    "setting": f"rtol {tol:.0e}",
                    "error": err,
                    "s_per_point": t,
                    "nfev": nfev,
                }
            )
            if t > slow:
                break
    for method in FIXED:
        for n in steps:
            if method == "collocation" and n < 16:
                continue
            err, t, nfev = measure(method, steps_per_period=n)
            rows.append(
                {
                    "method": method,
                    "setting": f"{n} steps/period",
                    "error": err,
                    "s_per_point": t,
                    "nfev": nfev,
                }
            )
    for r in rows:
        r["window_periods"] = tr + per
    return rows


def pareto_front(rows: list[dict]) -> list[dict]:
    front = []
    for r in sorted(rows, key=lambda r: (r["s_per_point"], r["error"])):
        if math.isfinite(r["error"]) and (not front or r["error"] < front[-1]["error"]):
            front.append(r)
    return front


# ---------------------------------------------------------------- 4. features
FEATURES = [
    ("reference (3 harmonics, polynomial 7, TE on)", {}),
    ("stiffness harmonics 0", {"stiffness_harmonics": 0}),
    ("stiffness harmonics 1", {"stiffness_harmonics": 1}),
    ("backlash linear", {"backlash": "linear"}),
    ("backlash dead zone", {"backlash": "dead-zone"}),
    ("backlash polynomial 3", {"backlash_order": 3}),
    ("backlash polynomial 5", {"backlash_order": 5}),
    ("backlash smooth", {"backlash": "smooth"}),
    ("transmission error off", {"transmission_error": False}),
]


def _variant(tmp: Path, name: str, changes: dict) -> Path:
    """The light-load scene with some [features] changed, derived into tmp."""
    from gearsym.derive import derive_model, load_target, variant
    from gearsym.derive.emit.python import emit_module, write_atomic
    from gearsym.derive.input.scene import builtin_root

    scene = load_target(builtin_root() / "reference-light.toml")
    model = derive_model(variant(scene, name.replace("_", "-"), **changes))
    path = tmp / "generated" / f"{model.name}.py"
    write_atomic(path, emit_module(model, "gearsym bench"))
    return path


def features(quick: bool) -> list[dict]:
    from gearsym.solver.integrate import default_initial_state
    from gearsym.solver.integrate.native import run_batch
    from gearsym.solver.system import System

    lam = np.linspace(0.0, 1.0, 20 if quick else 100)
    tr, per = (100, 20) if quick else (300, 100)
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        base_x = None
        for k, (label, changes) in enumerate(FEATURES):
            path = _variant(Path(tmp), f"feature_{k}", changes)
            system = System.load(path)
            module = system.module
            P = np.array([module.parameters(**{"lambda": v}) for v in lam])
            X0 = np.repeat(default_initial_state(system)[None, :], len(lam), axis=0)
            run_batch(module, P[:1], X0[:1], transient=1, periods=1)
            t, res = _median_time(
                lambda m=module, P=P, X0=X0: run_batch(
                    m, P, X0, method="dop853", transient=tr, periods=per
                ),
                3,
            )
            x = res.x[:, :-1, :2]
            if base_x is None:
                base_x = x
            rows.append(
                {
                    "feature": label,
                    "operations_rhs": module.OPERATIONS["rhs"],
                    "ms_per_point": 1e3 * t / len(lam),
                    "nfev_per_point": float(np.median(res.nfev)),
                    "max_change_poincare_u_v": float(np.nanmax(np.abs(x - base_x))),
                    "median_change_poincare_u_v": float(np.nanmedian(np.abs(x - base_x))),
                }
            )
    return rows


# ---------------------------------------------------------------- 5. scaling
def scaling(quick: bool) -> dict:
    from gearsym.solver.integrate import default_initial_state, native
    from gearsym.solver.integrate.native import run_batch
    from gearsym.solver.system import System

    sizes = [1, 10, 100] if quick else [1, 10, 100, 1000]
    module, _, _, _ = _reference()
    out = {"sweep_size": [], "meshes": []}
    for n in sizes:
        _, lam, P, X0 = _reference(np.linspace(0, 1, n))
        t, _ = _median_time(
            lambda P=P, X0=X0: run_batch(
                module, P, X0, method="dop853", transient=300, periods=100
            ),
            3,
        )
        out["sweep_size"].append({"points": n, "s": t, "ms_per_point": 1e3 * t / n})
    with tempfile.TemporaryDirectory() as tmp:
        os.environ["GEARSYM_CACHE"] = tmp
        native.reset()
        try:
            for name in ("siso", "diso", "tiso"):
                system = System.load(name)
                started = time.perf_counter()
                _, facts = native.library(system.module)
                compile_s = time.perf_counter() - started
                m = system.module
                P = np.repeat(system.p[None, :], 100, axis=0)
                X0 = np.repeat(default_initial_state(system)[None, :], 100, axis=0)
                t, res = _median_time(
                    lambda m=m, P=P, X0=X0: run_batch(
                        m, P, X0, method="dop853", transient=300, periods=100
                    ),
                    3,
                )
                out["meshes"].append(
                    {
                        "model": name,
                        "meshes": len(m.COORDINATES),
                        "operations_rhs": m.OPERATIONS["rhs"],
                        "compile_s": compile_s,
                        "ms_per_point": 1e3 * t / 100,
                        "nfev_per_point": float(np.median(res.nfev)),
                    }
                )
        finally:
            os.environ.pop("GEARSYM_CACHE", None)
            native.reset()
    return out


# ---------------------------------------------------------------- report
def _fmt(x, digits=3):
    if isinstance(x, float) and not math.isfinite(x):
        return "–"
    return f"{x:.{digits}g}"


def write_doc(
    res: dict, path: Path, figure: Path | None = None, command: str | None = None
) -> None:
    """Write the report of ``run``'s result to ``path`` and, unless None, the Pareto
    figure to ``figure`` (the report links it by name, so keep both in one folder).
    ``command`` is the command the report says wrote it."""
    if command is None:
        command = f"gearsym bench{' --quick' if res['quick'] else ''}"
    h, th = res["headline"], res["throughput"]
    cpu = os.cpu_count()
    lines = [
        "# Performance: speed against accuracy",
        "",
        f"Written by `{command}` on "
        f"{res['date']} ({cpu} cores; the machine is shared, so every time is the median of "
        "repeated runs and every ratio is measured within the same run). "
        "Code: `benchmarks/performance.py`, `benchmarks/lockstep_reference.c`.",
        "",
        "## Headline: the light-load load-ratio sweep",
        "",
        f"{h['points']} values of λ on [0, 1], {h['transient_periods']} transient + "
        f"{h['sampled_periods']} sampled periods each, rtol 1e-8, atol 1e-10, the reference "
        "model (`reference_light`).",
        "",
        "| run | time for the sweep (s) | evaluations per point | max Poincaré error |",
        "|---|---|---|---|",
        f"| baseline: `solve_ivp(RK45)`, hand-written Python right-hand side "
        f"({h['baseline_points_timed']} points timed, × {h['points']}) | "
        f"{_fmt(h['baseline_s_400'])} | {h['baseline_nfev_per_point']:.0f} | "
        f"{_fmt(h['baseline_max_poincare_error'])} |",
        f"| the same with SciPy's DOP853 (the compiled method's algorithm) | "
        f"{_fmt(h['baseline_dop853_s_400'])} | {h['baseline_dop853_nfev_per_point']:.0f} | "
        f"{_fmt(h['baseline_dop853_max_poincare_error'])} |",
        f"| compiled batched DOP853 (`gearsym.solver.integrate.native`), 1 core | "
        f"{_fmt(h['compiled_1_core_s'])} | {h['compiled_nfev_per_point']:.0f} | "
        f"{_fmt(h['compiled_max_poincare_error'])} |",
        f"| compiled batched DOP853, 2 processes | {_fmt(h['compiled_2_cores_s'])} | | |",
        f"| hand-written vectorised lockstep DOP853 in C, 1 core | {_fmt(h['reference_c_s'])} | "
        f"{h['reference_c_nfev_per_point']:.0f} | {_fmt(h['reference_c_max_poincare_error'])} |",
        "",
        f"**Speed-up over the baseline: {h['speedup_1_core']:.0f}× on one core, "
        f"{h['speedup_2_cores']:.0f}× on two**; over the same plain right-hand side under "
        f"SciPy's DOP853 (same algorithm as the compiled run, so the ratio is what compiling "
        f"and batching alone bring): {h['speedup_1_core_vs_dop853_baseline']:.0f}× on one core. "
        f"The compiled backend takes {h['over_reference_1_core']:.2f}× the time of the "
        f"hand-written C. Poincaré errors against {h['accuracy_reference']} (which agrees with "
        "SciPy's DOP853 at rtol 1e-13 to about 2e-10 over this window). Two-core times vary "
        "most with the machine's other load.",
        "",
        "## Throughput of one-point-at-a-time integration",
        "",
        f"- right-hand side alone (C loop): {th['rhs_only_evals_per_s'] / 1e6:.1f} million "
        "evaluations per second;",
        f"- DOP853 one point at a time (what continuation sweeps use): "
        f"{th['one_point_dop853_evals_per_s'] / 1e6:.1f} million evaluations per second, "
        f"{th['one_point_dop853_ms_per_point']:.2f} ms per 400-period point.",
        "",
        "## Speed against accuracy, every back end",
        "",
        f"Error: largest difference of the Poincaré points from SciPy's Radau at rtol 1e-12 "
        "(an implicit method, independent of the explicit ones measured), "
        f"over λ points spread on [0.1, 0.9] and a {res['pareto'][0]['window_periods']}-period "
        "window; time per point (median). Adaptive methods at atol = rtol/100; fixed-step ones "
        "by steps per period. A method stops at the first setting slower than 5 s per point.",
        "",
    ]
    if figure is not None:
        lines += [f"![Pareto]({figure.name})", ""]
    lines += [
        "| method | setting | max error | s per point | evaluations |",
        "|---|---|---|---|---|",
    ]
    front = {(r["method"], r["setting"]) for r in pareto_front(res["pareto"])}
    for r in res["pareto"]:
        mark = " **(Pareto)**" if (r["method"], r["setting"]) in front else ""
        lines.append(
            f"| {r['method']} | {r['setting']}{mark} | {_fmt(r['error'])} | "
            f"{_fmt(r['s_per_point'])} | {r['nfev']} |"
        )
    lines += [
        "",
        "## What each model feature costs",
        "",
        "Compiled batched DOP853 over λ ∈ [0, 1]; the change is the largest (and median) "
        "difference of the Poincaré points of u and v from the reference model at the same λ "
        "(the modelling effect of the feature, not an integration error).",
        "",
        "| model | rhs operations | ms per point | evaluations per point | max change | "
        "median change |",
        "|---|---|---|---|---|---|",
    ]
    for r in res["features"]:
        lines.append(
            f"| {r['feature']} | {r['operations_rhs']} | {r['ms_per_point']:.2f} | "
            f"{r['nfev_per_point']:.0f} | {_fmt(r['max_change_poincare_u_v'])} | "
            f"{_fmt(r['median_change_poincare_u_v'])} |"
        )
    sc = res["scaling"]
    lines += [
        "",
        "## Scaling",
        "",
        "| sweep points | s | ms per point |",
        "|---|---|---|",
        *(f"| {r['points']} | {r['s']:.3f} | {r['ms_per_point']:.2f} |" for r in sc["sweep_size"]),
        "",
        "| model | meshes | rhs operations | compile (s, once per model) | ms per point | "
        "evaluations per point |",
        "|---|---|---|---|---|---|",
        *(
            f"| {r['model']} | {r['meshes']} | {r['operations_rhs']} | {r['compile_s']:.2f} | "
            f"{r['ms_per_point']:.2f} | {r['nfev_per_point']:.0f} |"
            for r in sc["meshes"]
        ),
        "",
    ]
    lines += floors_lines(res)
    for section in SECTIONS:
        if section.name in res:
            lines += section.write(res)
    path.write_text("\n".join(lines), encoding="utf-8")
    if figure is not None:
        _plot(res["pareto"], figure)


def _plot(rows, path):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7.5, 4.8))
    for method in dict.fromkeys(r["method"] for r in rows):
        pts = [
            (r["s_per_point"], r["error"])
            for r in rows
            if r["method"] == method and math.isfinite(r["error"]) and r["error"] > 0
        ]
        if pts:
            x, y = zip(*pts, strict=True)
            ax.loglog(x, y, "o-", ms=3, lw=1, label=method)
    ax.set_xlabel("seconds per sweep point")
    ax.set_ylabel("max error of the Poincaré points")
    ax.legend(fontsize=8, ncol=2)
    ax.grid(True, which="major", alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=110, metadata={"Software": None})
    plt.close(fig)


# ---------------------------------------------------------------- 6. appended sections
@dataclass(frozen=True)
class Section:
    """A section appended to the report after the five above.

    ``measure(quick, res)`` runs after every earlier section (``res`` holds their results,
    e.g. ``res["headline"]["baseline_s_per_point"]``, the baseline timed in this run) and
    returns a JSON-able dict, kept as ``res[name]``; ``write(res)`` returns the section's
    Markdown lines.  Append a :class:`Section` to :data:`SECTIONS` to add one.
    """

    name: str
    measure: Callable[[bool, dict], dict]
    write: Callable[[dict], list[str]]


SWEEP_POINTS = 400


def _sweep_command(points: int, out: str, *extra: str) -> list[str]:
    """The user-facing command: 400 independent points, Poincare points and verdicts
    (classification per coordinate, Max/Min), no exponent."""
    return [sys.executable, "-m", "gearsym", "sweep", "reference-light", "--param=lambda",
            f"--range=0:1:{points}", "--independent", "--lyapunov-periods=0", "--quiet",
            *extra, f"--out={out}"]  # fmt: skip


def _wall(cmd: list[str]) -> float:
    started = time.perf_counter()
    done = subprocess.run(cmd, capture_output=True, text=True, env=os.environ.copy())
    took = time.perf_counter() - started
    if done.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd[2:5])} failed: {done.stderr.strip()[-300:]}")
    return took


def cli_sweep(quick: bool, res: dict) -> dict:
    """Median wall time of the user-facing ``gearsym sweep`` of 400 independent points,
    each run a new process into a new folder (start-up, imports, model load, the compiled
    library from its cache, integration, verdicts, the store, sweep.json and the figure
    all included); the ratio to the ``solve_ivp(RK45)`` baseline of this run."""
    repeats = 3 if quick else 7
    points = SWEEP_POINTS
    load = os.getloadavg()[0]  # the runs need two free cores: say how busy the machine was
    with tempfile.TemporaryDirectory() as tmp:
        _wall(_sweep_command(points, f"{tmp}/warm"))  # the compile cache is warm after this
        times, bare = [], []
        for k in range(repeats):  # interleaved, so that both see the same machine load
            times.append(_wall(_sweep_command(points, f"{tmp}/run{k}")))
            bare.append(_wall(_sweep_command(points, f"{tmp}/bare{k}", "--no-figure")))
        data = json.loads(Path(f"{tmp}/run0/sweep.json").read_text(encoding="utf-8"))
        help_s = statistics.median(
            _wall([sys.executable, "-m", "gearsym", "sweep", "--help"]) for _ in range(3)
        )
    coords = list(data["points"][0]["classification"])
    motions = {
        c: sorted({p["classification"][c]["motion"] for p in data["points"]}) for c in coords
    }
    baseline = res["headline"]["baseline_s_per_point"] * points
    median = statistics.median(times)
    return {
        "points": points,
        "command": " ".join(["gearsym", *_sweep_command(points, "OUT")[3:-1]]),
        "runs_s": times,
        "median_s": median,
        "ms_per_point": 1e3 * median / points,
        "start_up_s": help_s,
        "load_average": load,
        "no_figure_runs_s": bare,
        "no_figure_median_s": statistics.median(bare),
        "baseline_s": baseline,
        "speedup": baseline / median,
        "motions": motions,
    }


def cli_sweep_lines(res: dict) -> list[str]:
    r = res["cli_sweep"]
    h = res["headline"]
    return [
        "## The user-facing sweep, start-up included",
        "",
        f"`{r['command']} --out OUT` as a user types it: a new process each time (start-up, "
        "imports, model load, the compiled library from its cache), every point integrated "
        "in the compiled lockstep engine, classified per coordinate (Poincaré points, "
        "Max/Min, no exponent), written to the store, `sweep.json` and the bifurcation "
        f"figure. Wall time, median of {len(r['runs_s'])} runs after one that warms the "
        f"cache; the machine's load average before the runs was {r.get('load_average', 0):.1f} "
        f"on {os.cpu_count()} cores (the command uses two processes: other work on the "
        "machine slows it more than the one-core baseline).",
        "",
        "| run | wall time (s) | per point (ms) |",
        "|---|---|---|",
        "| baseline: `solve_ivp(RK45)`, plain Python right-hand side "
        f"({_fmt(h['baseline_s_per_point'])} s per point, timed in this run, × {r['points']}) "
        f"| {_fmt(r['baseline_s'])} | "
        f"{_fmt(1e3 * r['baseline_s'] / r['points'])} |",
        f"| `gearsym sweep`, the whole command | {r['median_s']:.2f} | {r['ms_per_point']:.2f} |",
        f"| the same with `--no-figure` (sweep.json only; matplotlib not loaded) | "
        f"{r['no_figure_median_s']:.2f} | {1e3 * r['no_figure_median_s'] / r['points']:.2f} |",
        f"| start-up alone (`gearsym sweep --help`) | {r['start_up_s']:.2f} | |",
        "",
        f"**{r['speedup']:.0f}× faster than the baseline, start-up included** (floor of issue "
        "12: 500×). Runs (s): "
        + ", ".join(f"{t:.2f}" for t in r["runs_s"])
        + ". Verdicts: "
        + "; ".join(f"{c}: {', '.join(m)}" for c, m in r["motions"].items())
        + ".",
        "",
    ]


def _maps(quick: bool, res: dict) -> dict:
    from gearsym.benchmarks.atlas import map_speed

    return map_speed(quick)


def _maps_lines(res: dict) -> list[str]:
    from gearsym.benchmarks.atlas import map_section

    return map_section(res["maps"])


def _response(quick: bool, res: dict) -> dict:
    from gearsym.benchmarks.response import response_speed

    return response_speed(quick)


def _response_lines(res: dict) -> list[str]:
    from gearsym.benchmarks.response import response_section

    return response_section(res["response"])


def _dofs(quick: bool, res: dict) -> dict:
    from gearsym.benchmarks.dofs import dof_cost

    return dof_cost(quick)


def _dofs_lines(res: dict) -> list[str]:
    from gearsym.benchmarks.dofs import dof_section

    return dof_section(res["dofs"])


SECTIONS: list[Section] = [
    Section("cli_sweep", cli_sweep, cli_sweep_lines),
    Section("maps", _maps, _maps_lines),
    Section("response", _response, _response_lines),
    Section("dofs", _dofs, _dofs_lines),
]


def floors_lines(res: dict) -> list[str]:
    """The speed floors of issues 12 and 13, side by side, as far as this run measured
    them."""
    rows = []
    if "cli_sweep" in res:
        r = res["cli_sweep"]
        rows.append(
            f"| `gearsym sweep` of {r['points']} independent points against `solve_ivp(RK45)` "
            f"with a plain Python right-hand side, start-up included | ≥ 500× | "
            f"**{r['speedup']:.0f}×** ({r['median_s']:.2f} s against {_fmt(r['baseline_s'])} s) |"
        )
    if "maps" in res:
        m = res["maps"]
        nx, ny = m["grid"]
        rows.append(
            f"| `gearsym map`, {nx} × {ny} × {m['initial_states']} initial states, 300 + 100 "
            f"periods, exponent over 200, {m['workers']} processes | ≤ 60 s | "
            f"**{m['with_exponent']['median_s']:.1f} s** |"
        )
    if "response" in res:
        r = res["response"]
        rows.append(
            f"| harmonic balance over {r['points']} frequencies of the reference model (issue "
            f"13; {r['hb']['curve_points']} points with the overhangs, Hill's stability, folds "
            f"located), one core | ≤ 2 s | **{r['hb']['median_s']:.2f} s** |"
        )
    if not rows:
        return []
    return [
        "## Speed floors (issues 12 and 13), measured side by side in this run",
        "",
        "| floor | required | measured |",
        "|---|---|---|",
        *rows,
        "",
    ]


def run(quick: bool) -> dict:
    res = {"quick": quick, "date": time.strftime("%Y-%m-%d")}
    steps = [
        ("headline", headline),
        ("throughput", throughput),
        ("pareto", pareto),
        ("features", features),
        ("scaling", scaling),
    ]
    steps += [(s.name, lambda quick, s=s: s.measure(quick, res)) for s in SECTIONS]
    for name, fn in steps:
        started = time.perf_counter()
        print(f"bench: {name} ...", file=sys.stderr, flush=True)
        res[name] = fn(quick)
        print(f"bench: {name} done in {time.perf_counter() - started:.0f} s", file=sys.stderr)
    return res


def output_files(out: Path | str | None = None, *, docs: bool = False) -> tuple[Path, Path]:
    """The report and figure paths: in ``out`` (default ``bench-out``) or, with ``docs``,
    in the checkout's ``docs/``; the folder is created if missing and checked for writing.

    Raises :class:`OutputError` (one line) when both are given, outside a checkout with
    ``docs``, or when the folder cannot be written.
    """
    if docs and out is not None:
        raise OutputError(
            "--docs and --out both given: --docs writes the checkout's docs/, --out DIR "
            "another folder; give one"
        )
    folder = checkout_docs() if docs else Path(DEFAULT_OUT if out is None else out)
    folder = output_folder(folder, (REPORT, FIGURE))
    return folder / REPORT, folder / FIGURE


def main(argv: list[str] | None = None) -> int:
    """``gearsym bench``: check the output folder, run, write the report and figure.

    Raises :class:`OutputError` before any benchmark runs when the output is unusable.
    """
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="fewer points and repeats")
    parser.add_argument("--json", action="store_true", help="also print every figure as JSON")
    parser.add_argument("--out", type=Path, metavar="DIR", help=f"default {DEFAULT_OUT}")
    parser.add_argument("--docs", action="store_true", help="write the checkout's docs/")
    args = parser.parse_args(argv)
    report, figure = output_files(args.out, docs=args.docs)
    res = run(args.quick)
    command = "gearsym bench" + " --quick" * args.quick + " --docs" * args.docs
    write_doc(res, report, figure, command)
    if args.json:
        from gearsym.solver._json import dumps

        print(dumps(res, indent=2))
    else:
        print(f"wrote {report} and {figure}")
    return 0


if __name__ == "__main__":
    run_script(main)
