"""The reference model of the benchmarks, the plain baseline and the hand-written C.

The 400-point light-load sweep over the load ratio (``reference_light``), the right-hand
side a user would write by hand (plain Python, ``solve_ivp``), and the hand-written
vectorised lockstep DOP853 of ``lockstep_reference.c`` that the compiled engine is timed
against; shared by ``performance.py``, ``peers.py`` and ``floors.py``.
"""

from __future__ import annotations

import ctypes
import math
import statistics
import subprocess
import time
from pathlib import Path

import numpy as np


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


def _fmt(x, digits=3):
    if isinstance(x, float) and not math.isfinite(x):
        return "–"
    return f"{x:.{digits}g}"


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


def tight_reference(module, P, X0, subset, transient: int, periods: int) -> np.ndarray:
    """Poincare points (len(subset), periods, n) by CVODES (BDF) at rtol 1e-13, atol 1e-15:
    the independent reference every accuracy figure of the sweep is measured against."""
    from gearsym.solver.integrate import simulate
    from gearsym.solver.system import System

    runs = [
        simulate(
            System(module, P[i]),
            X0[i],
            method="cvodes",
            rtol=1e-13,
            atol=1e-15,
            transient=transient,
            periods=periods,
            samples_per_period=1,
        ).x.T
        for i in subset
    ]
    return np.array(runs)


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
