"""The reference model's frequency response by the three methods, side by side.

The light-load reference model (stated values) over omega in [0.3, 0.9] at a resolution of
400 frequencies: harmonic-balance continuation (H = 15, Hill's stability, folds located),
shooting continuation (monodromy, folds located) and the up and down time-integration
sweeps in the compiled engine (both in one lockstep group in the excitation phase).  Each
method's error is its agreement with an independent method at eight of its own points:
harmonic balance against shooting from its state (tolerance 1e-12), shooting against
harmonic balance (H = 32) from its state, integration (mean and RMS) against harmonic
balance from its Poincare state.  One core (the bench sets one BLAS thread); times are
medians of repeated runs (shooting: one run).

Run through ``gearsym bench`` (a section of performance.md) or on its own:
``python -m gearsym.benchmarks.response [--quick]``.
"""

from __future__ import annotations

import statistics
import sys
import time

import numpy as np

__all__ = ["response_section", "response_speed"]

RANGE = (0.3, 0.9)


def _timed(fn, repeats: int):
    times, out = [], None
    for _ in range(repeats):
        t = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t)
    return out, statistics.median(times)


def _picks(n: int, k: int = 8) -> list[int]:
    return sorted({int(i) for i in np.linspace(0, n - 1, k)})


def response_speed(quick: bool = False, repeats: int = 3) -> dict:
    from gearsym.solver.periodic import shoot
    from gearsym.solver.periodic.harmonic_balance import harmonic_balance
    from gearsym.solver.sweep.frequency import frequency_response
    from gearsym.solver.system import System

    system = System.load("reference_light")
    points = 100 if quick else 400
    out: dict = {"points": points, "range": list(RANGE), "model": system.name}

    def run(method):
        return frequency_response(system, "omega", *RANGE, points=points, methods=(method,))

    run("integration")  # compile the engine's library outside the timing
    hb, t_hb = _timed(lambda: run("hb"), repeats)
    integ, t_int = _timed(lambda: run("integration"), repeats)
    sh, t_sh = _timed(lambda: run("shooting"), 1)

    # harmonic balance against shooting from its own states
    errs = []
    c0 = hb.curves[0]
    for k in _picks(len(c0.values)):
        s = system.with_values(omega=float(c0.values[k]))
        x0 = c0.states[k]
        try:
            orbit = shoot(s, x0, 1, tol=1e-12)
            errs.append(float(np.max(np.abs(orbit.x0 - x0))))
        except Exception:  # noqa: BLE001 (a point at a fold: shooting is singular there)
            continue
    out["hb"] = {
        "median_s": t_hb,
        "curve_points": int(sum(len(c.values) for c in hb.curves)),
        "folds": [e.value for e in c0.events if e.kind == "fold"],
        "error": max(errs) if errs else None,
        "checked": len(errs),
    }
    # shooting against harmonic balance from its states
    errs = []
    c1 = sh.curves[0]
    for k in _picks(len(c1.values)):
        s = system.with_values(omega=float(c1.values[k]))
        x0 = c1.states[k]
        try:
            sol = harmonic_balance(s, x0, harmonics=32, stability=False)
            errs.append(float(np.max(np.abs(sol.state(0.0) - x0))))
        except Exception:  # noqa: BLE001
            continue
    out["shooting"] = {
        "median_s": t_sh,
        "curve_points": len(c1.values),
        "folds": [e.value for e in c1.events if e.kind == "fold"],
        "error": max(errs) if errs else None,
        "checked": len(errs),
    }
    # integration: mean and RMS against harmonic balance from the Poincare state
    errs = []
    up = integ.curves[0]
    for k in _picks(len(up.values), 12):
        if not up.stats["u"]["poincare_spread"][k] < 1e-8:
            continue
        s = system.with_values(omega=float(up.values[k]))
        state = np.array(up.details["poincare"][k][-1])
        try:
            sol = harmonic_balance(s, state, harmonics=32, stability=False)
        except Exception:  # noqa: BLE001
            continue
        errs.append(
            max(
                max(
                    abs(sol.mean(c) - up.stats[c]["mean"][k]),
                    abs(sol.rms(c) - up.stats[c]["rms"][k]),
                )
                for c in system.coordinates
            )
        )
    out["integration"] = {
        "median_s": t_int,
        "curve_points": 2 * len(up.values),
        "settle": up.details["settle_periods"],
        "sampled": up.details["sampled_periods"],
        "error": max(errs) if errs else None,
        "checked": len(errs),
    }
    return out


def _e(v) -> str:
    return "—" if v is None else f"{v:.1e}"


def response_section(r: dict) -> list[str]:
    """The performance.md section of :func:`response_speed`'s result."""
    n = r["points"]
    hb, sh, it = r["hb"], r["shooting"], r["integration"]
    floor = " (floor of issue 13: 2 s)" if n == 400 else ""
    return [
        "## Frequency response: harmonic balance, shooting and integration",
        "",
        f"The light-load reference model over ω̄ ∈ [{r['range'][0]}, {r['range'][1]}] at a "
        f"resolution of {n} frequencies (the parameter moves at most the range over {n} per "
        "step; a continuation adds the points round its folds), one core. Error: agreement "
        "with an independent method at eight of the method's own points (harmonic balance: "
        "shooting from its state, max state difference; shooting: harmonic balance with "
        "H = 32 from its state; integration: mean and RMS against harmonic balance from its "
        "Poincaré state). Code: `benchmarks/response.py`.",
        "",
        "| method | wall time (s) | points on the curve | folds located | error (points checked) |",
        "|---|---|---|---|---|",
        f"| harmonic balance (H = 15, Hill's stability){floor}, median | {hb['median_s']:.2f} | "
        f"{hb['curve_points']} | {', '.join(f'{f:.5f}' for f in hb['folds'])} | "
        f"{_e(hb['error'])} ({hb['checked']}) |",
        f"| shooting continuation (monodromy), once | {sh['median_s']:.1f} | "
        f"{sh['curve_points']} | {', '.join(f'{f:.5f}' for f in sh['folds'])} | "
        f"{_e(sh['error'])} ({sh['checked']}) |",
        f"| integration, up and down sweeps in lockstep ({it['settle']} + {it['sampled']} "
        f"periods per frequency), median | {it['median_s']:.2f} | {it['curve_points']} | "
        f"(jumps) | {_e(it['error'])} ({it['checked']}) |",
        "",
    ]


if __name__ == "__main__":
    res = response_speed("--quick" in sys.argv)
    from gearsym.solver._json import dumps

    print(dumps(res, indent=1))
    print("\n".join(response_section(res)))
