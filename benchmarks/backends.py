"""Sections 1 to 5 of ``performance.py``: headline, throughput, Pareto, features, scaling.

Each function measures one section and returns its JSON-able result (``performance.run``
keeps it under the section's name; ``performance.write_doc`` writes it).
"""

from __future__ import annotations

import math
import os
import statistics
import tempfile
import time
from pathlib import Path

import numpy as np

# absolute, so that ``python benchmarks/performance.py`` runs too
from gearsym.benchmarks.baseline import (
    _median_time,
    _reference,
    _reference_library,
    baseline_point,
    reference_run,
    tight_reference,
)


# ---------------------------------------------------------------- 1. headline
def headline(quick: bool) -> dict:
    from gearsym.solver.integrate.native import run_batch

    module, lam, P, X0 = _reference()
    tr, per = 300, 100
    reps = 3
    # independent reference for the accuracy comparison: CVODES (BDF) at rtol 1e-13
    subset = np.linspace(0, len(lam) - 1, 2 if quick else 6).round().astype(int)
    tight = tight_reference(module, P, X0, subset, tr, per)
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
ADAPTIVE = ["RK45", "scipy-dop853", "LSODA", "Radau", "cvodes", "dopri5", "dop853"]
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
