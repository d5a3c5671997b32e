"""What the compiled libraries' optimisation level buys: -O2 against -O3, per model.

Run: ``python benchmarks/compile_flags.py [--repeats 3] [--points 40]`` (prints a
Markdown table; nothing is written).  Per model, a sweep of ``points`` points (the
DI-SO over lambda in [0, 1], the others over the damping ratio 0.01 to 0.1) of
200 + 100 periods in the compiled batched DOP853, the two levels alternating, the median
of ``repeats`` each; and the compile of the model's plain library on an empty cache,
the median of ``repeats``.  The choice it measures is ``native/compiler.level``'s: -O3 for a
smooth model's batch libraries (their lockstep loops vectorise), and for its one-point
library from 12 states on; -O2 otherwise (``native/compiler.py`` says why).
"""

from __future__ import annotations

import argparse
import shutil
import statistics
import sys
import tempfile
import time

import numpy as np

CASES = (
    ("reference-light", "lambda", False),
    ("reference-light", "lambda", True),
    ("reference-dead-zone", "lambda", False),
    ("diso-bearings-light", "lambda", False),
    ("two-stage", "damping_ratio", False),
)
LEVELS = ("-O2", "-O3")


def measure(repeats: int, points: int) -> list[dict]:
    import os

    os.environ["GEARSYM_CACHE"] = tempfile.mkdtemp(prefix="gearsym-flags-")
    from gearsym.resolve import module_for
    from gearsym.solver.integrate import default_initial_state
    from gearsym.solver.integrate.native import build, reset, run_batch
    from gearsym.solver.system import System

    flags = sys.modules["gearsym.solver.integrate.native.compiler"]
    base, smooth = flags._FLAGS[1:], flags._SMOOTH_FLAGS

    def level_flags(level: str) -> None:  # every library at ``level``
        flags._FLAGS, flags._SMOOTH_FLAGS = (level, *base), (level,)

    rows = []
    try:
        for scene, param, tangent in CASES:
            module = module_for(scene)
            system = System.load(module)
            lo, hi = (0.01, 0.1) if param == "damping_ratio" else (0.0, 1.0)
            P = np.array([module.parameters(**{param: v}) for v in np.linspace(lo, hi, points)])
            X0 = np.repeat(np.asarray(default_initial_state(system))[None, :], points, axis=0)
            kw = {"collect": ("samples", "exponent")} if tangent else {}
            run_ms: dict = {level: [] for level in LEVELS}
            compile_s: dict = {level: [] for level in LEVELS}
            for _ in range(repeats):
                for level in LEVELS:
                    level_flags(level)
                    reset()
                    shutil.rmtree(build.cache_dir(), ignore_errors=True)
                    started = time.perf_counter()
                    build.library(module, tangent, ())
                    compile_s[level].append(time.perf_counter() - started)
                    warm = dict(kw, lyapunov_periods=2) if tangent else {}
                    run_batch(module, P, X0, method="dop853", transient=1, periods=1, **warm)
                    full = dict(kw, lyapunov_periods=300) if tangent else {}
                    started = time.perf_counter()
                    run_batch(module, P, X0, method="dop853", transient=200, periods=100, **full)
                    run_ms[level].append(1e3 * (time.perf_counter() - started) / points)
            rows.append(
                {
                    "model": scene + (" with the tangent" if tangent else ""),
                    "states": len(module.STATES),
                    "piecewise": bool(system.piecewise),
                    **{f"ms {lv}": statistics.median(run_ms[lv]) for lv in LEVELS},
                    **{f"compile {lv}": statistics.median(compile_s[lv]) for lv in LEVELS},
                }
            )
    finally:
        flags._FLAGS, flags._SMOOTH_FLAGS = ("-O2", *base), smooth
    return rows


def table(rows: list[dict]) -> str:
    lines = [
        "| model | states | piecewise | ms a point -O2 | ms a point -O3 | compile -O2 (s) "
        "| compile -O3 (s) |",
        "|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        lines.append(
            f"| {r['model']} | {r['states']} | {'yes' if r['piecewise'] else 'no'} "
            f"| {r['ms -O2']:.2f} | {r['ms -O3']:.2f} | {r['compile -O2']:.2f} "
            f"| {r['compile -O3']:.2f} |"
        )
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=3, help="repeats of each (default: 3)")
    parser.add_argument("--points", type=int, default=40, help="sweep points (default: 40)")
    args = parser.parse_args(argv)
    print(table(measure(args.repeats, args.points)))
    return 0


if __name__ == "__main__":
    sys.exit(main())
