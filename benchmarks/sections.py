"""Section 6 of ``performance.py``: the sections appended after the five measured ones.

The user-facing ``gearsym sweep`` of 400 independent points (start-up included), the
regime maps, the frequency response and the cost of the degrees of freedom, each a
:class:`Section` of :data:`SECTIONS`, and the table of the speed floors side by side.
"""

from __future__ import annotations

import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

# absolute, so that ``python benchmarks/performance.py`` runs too
from gearsym.benchmarks.baseline import _fmt


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
    options = ["--param=lambda", f"--range=0:1:{points}", "--independent"]
    options += ["--lyapunov-periods=0", "--quiet", *extra, f"--out={out}"]
    return [sys.executable, "-m", "gearsym", "sweep", "reference-light", *options]


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
