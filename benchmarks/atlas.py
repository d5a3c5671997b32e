"""Speed of regime maps: the 50 x 50 map of the reference model with 4 initial states.

10,000 runs of 300 transient + 100 sampled periods each, with the largest Lyapunov
exponent summed over the last 200 periods (the tangent vector integrated beside the state
from the start), on the compiled map engine (``solver/integrate/native/maps.py``) and two
processes; the same without the exponent; and the whole ``gearsym map`` command (start-up,
the map, map.json/map.csv and five figures) once.  Times are medians of repeated runs.

Run through ``gearsym bench`` (a section of performance.md) or on its own:
``python -m gearsym.benchmarks.atlas [--quick]``.
"""

from __future__ import annotations

import os
import statistics
import subprocess
import sys
import tempfile
import time

import numpy as np

__all__ = ["cli_sweep_speed", "floors_section", "map_section", "map_speed"]


def _grid(quick: bool) -> tuple[np.ndarray, np.ndarray]:
    n = 10 if quick else 50
    return np.linspace(0.0, 1.0, n), np.linspace(0.1, 0.5, n)


def map_speed(quick: bool = False, repeats: int = 3) -> dict:
    """Median wall times of the map with and without the exponent, and of the CLI."""
    from gearsym.resolve import load
    from gearsym.solver.sweep.atlas import regime_map

    system = load("reference-light")
    lam, f1 = _grid(quick)
    out: dict = {"grid": [len(lam), len(f1)], "initial_states": 4, "workers": 2}
    for label, lyap in (("with_exponent", 200), ("without_exponent", 0)):
        times, m = [], None
        for _ in range(1 if quick else repeats):
            started = time.perf_counter()
            m = regime_map(
                system,
                ("lambda", lam),
                ("f1", f1),
                initial_states=4,
                lyapunov_periods=lyap,
                workers=2,
            )
            times.append(time.perf_counter() - started)
        out[label] = {"median_s": statistics.median(times), "runs_s": times}
        if lyap:
            motions = m.grid("motion", "v").ravel()
            out["motion_v"] = {k: int((motions == k).sum()) for k in sorted(set(motions))}
            out["several_outcomes"] = int((m.grid("attractors") > 1).sum())
    with tempfile.TemporaryDirectory() as tmp:
        cmd = [
            sys.executable,
            "-m",
            "gearsym",
            "map",
            "reference-light",
            f"--x=lambda=0:1:{len(lam)}",
            f"--y=f1=0.1:0.5:{len(f1)}",
            "--workers=2",
            "--quiet",
            f"--out={tmp}/map",
        ]
        started = time.perf_counter()
        subprocess.run(cmd, check=True, capture_output=True, env=os.environ.copy())
        out["cli_s"] = time.perf_counter() - started
    return out


def map_section(r: dict) -> list[str]:
    """The performance.md section of :func:`map_speed`'s result."""
    nx, ny = r["grid"]
    runs = nx * ny * r["initial_states"]
    w, wo = r["with_exponent"], r["without_exponent"]
    floor = " (floor of issue 12: 60 s)" if (nx, ny) == (50, 50) else ""
    return [
        "## Regime maps",
        "",
        f"`gearsym map`: {nx} x {ny} grid of the reference model (λ on [0, 1] by f1 on "
        f"[0.1, 0.5]), {r['initial_states']} initial states per point (forward and backward "
        f"chains, 2 random): {runs} runs of 300 transient + 100 sampled periods, compiled "
        f"lockstep DOP853 at rtol 1e-8, {r['workers']} processes. Code: "
        "`benchmarks/atlas.py`.",
        "",
        "| run | wall time (s), median | per run (ms) |",
        "|---|---|---|",
        f"| with the exponent over the last 200 periods{floor} | {w['median_s']:.1f} | "
        f"{1e3 * w['median_s'] / runs:.2f} |",
        f"| without the exponent | {wo['median_s']:.1f} | {1e3 * wo['median_s'] / runs:.2f} |",
        f"| the whole command (start-up, map with exponent, files, 5 figures), once | "
        f"{r['cli_s']:.1f} | |",
        "",
        f"Motion of v over the grid (dominant attractor): {r.get('motion_v', {})}; grid "
        f"points with more than one outcome: {r.get('several_outcomes', 0)} of {nx * ny}.",
        "",
    ]


def cli_sweep_speed(quick: bool = False, repeats: int = 3) -> dict:
    """Median wall time of the user-facing ``gearsym sweep`` of 400 independent points
    (Poincare points and verdicts, no exponent), as a user runs it: a new process each
    time, start-up, the store, sweep.json and the figure included."""
    times = []
    points = 100 if quick else 400
    for _ in range(repeats):
        with tempfile.TemporaryDirectory() as tmp:
            cmd = [
                sys.executable,
                "-m",
                "gearsym",
                "sweep",
                "reference-light",
                "--param=lambda",
                f"--range=0:1:{points}",
                "--independent",
                "--lyapunov-periods=0",
                "--quiet",
                f"--out={tmp}/sweep",
            ]
            started = time.perf_counter()
            subprocess.run(cmd, check=True, capture_output=True, env=os.environ.copy())
            times.append(time.perf_counter() - started)
    return {"points": points, "median_s": statistics.median(times), "runs_s": times}


def floors_section(baseline_s_per_point: float, sweep: dict, maps: dict) -> list[str]:
    """The two speed floors of issue 12, measured in one run of ``gearsym bench``."""
    n = sweep["points"]
    baseline = baseline_s_per_point * n
    ratio = baseline / sweep["median_s"]
    w = maps["with_exponent"]["median_s"]
    nx, ny = maps["grid"]
    return [
        "## Speed floors of the regime-map work (issue 12), measured side by side",
        "",
        "| floor | required | measured in this run |",
        "|---|---|---|",
        f"| `gearsym sweep reference-light --param lambda --range 0:1:{n} --independent "
        f"--lyapunov-periods 0` (new process, start-up, store, sweep.json and figure "
        f"included; median of {len(sweep['runs_s'])}) against `solve_ivp(RK45)` with a "
        f"plain Python right-hand side ({baseline_s_per_point:.2f} s per point, headline "
        f"above, × {n} = {baseline:.0f} s) | ≥ 500× | **{sweep['median_s']:.2f} s: "
        f"{ratio:.0f}×** |",
        f"| `gearsym map`, {nx} × {ny} grid × {maps['initial_states']} initial states, "
        f"300 + 100 periods, exponent over 200 (median) | ≤ 60 s | **{w:.1f} s** |",
        "",
    ]


def main(argv: list[str] | None = None) -> int:
    quick = "--quick" in (argv if argv is not None else sys.argv[1:])
    print("\n".join(map_section(map_speed(quick))))
    return 0


if __name__ == "__main__":
    sys.exit(main())
