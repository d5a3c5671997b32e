"""The engine's speed floors and results, this checkout against another, in one run.

Run: ``python benchmarks/floors.py --before DIR [--repeats 5] [--out FILE]`` where ``DIR``
is another checkout of gearsym with its own virtual environment in ``DIR/.venv`` (for
example a ``git worktree`` of the commit before a change). Each measurement runs in a
fresh process of each checkout, the two alternating, ``--repeats`` times; the table
gives medians and the ratio after/before of the medians, so load on a shared machine
falls on both columns alike. It also checks that the results are the same: the Poincare
points of the 400-point sweep (largest difference), the regime map's motion labels and
the harmonic-balance curve.

Floors (issue 24): the 400-point sweep at least 550 times faster than the plain baseline
(``solve_ivp(RK45)`` with a hand-written right-hand side, ``performance.baseline_point``,
timed on six points and scaled to 400), the 50 x 50 x 4 regime map with the exponent in at
most 25 s on two workers, harmonic balance over 400 frequencies in at most 2 s, and
nothing slower than before by more than 5 %.
"""

from __future__ import annotations

import argparse
import json
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
CHILD = r"""
import json, sys, time
import numpy as np
what, out = sys.argv[1], sys.argv[2]
from gearsym.benchmarks import performance as perf
result = {}
if what == "sweep":
    module, lam, P, X0 = perf._reference()
    try:
        from gearsym.solver.integrate.run import Batch, integrate
        from gearsym.solver.integrate.spec import RunSpec
        spec = RunSpec(method="dop853", transient=300, periods=100)
        batch = Batch.of(module, P)
        go = lambda: integrate(batch, X0, spec).x
    except ImportError:
        from gearsym.solver.integrate.native import run_batch
        go = lambda: run_batch(module, P, X0, method="dop853", transient=300, periods=100).x
    go()  # compile outside the timing
    t = time.perf_counter(); x = go(); result["seconds"] = time.perf_counter() - t
    np.save(out + ".npy", x)
elif what == "baseline":
    module, lam, P, X0 = perf._reference()
    times = []
    for i in np.linspace(0, len(lam) - 1, 6).round().astype(int):
        t = time.perf_counter(); perf.baseline_point(module, P[i], X0[i], 300, 100)
        times.append(time.perf_counter() - t)
    result["seconds"] = float(np.median(times)) * len(lam)
elif what == "map":
    from gearsym.resolve import load
    from gearsym.solver.sweep.atlas import regime_map
    system = load("reference-light")
    lam, f1 = np.linspace(0.0, 1.0, 50), np.linspace(0.1, 0.5, 50)
    regime_map(system, ("lambda", lam[:2]), ("f1", f1[:2]), initial_states=1, workers=2)
    t = time.perf_counter()
    m = regime_map(system, ("lambda", lam), ("f1", f1), initial_states=4,
                   lyapunov_periods=200, workers=2)
    result["seconds"] = time.perf_counter() - t
    result["motion_v"] = [str(v) for v in m.grid("motion", "v").ravel()]
    result["motion_u"] = [str(v) for v in m.grid("motion", "u").ravel()]
elif what == "hb":
    from gearsym.solver.sweep.frequency import frequency_response
    from gearsym.solver.system import System
    system = System.load("reference_light")
    run = lambda: frequency_response(system, "omega", 0.3, 0.9, points=400, methods=("hb",))
    run()
    t = time.perf_counter(); r = run(); result["seconds"] = time.perf_counter() - t
    c = r.curves[0]
    np.save(out + ".npy", np.asarray(c.values, float))
json.dump(result, open(out, "w"))
"""
JOBS = ("sweep", "baseline", "map", "hb")


def _child(python: Path, what: str, out: Path) -> dict:
    subprocess.run([str(python), "-c", CHILD, what, str(out)], check=True)
    return json.loads(out.read_text())


def measure(before: Path, repeats: int, jobs=JOBS) -> dict:
    sides = {"before": before / ".venv/bin/python", "after": Path(sys.executable)}
    runs: dict = {side: {job: [] for job in jobs} for side in sides}
    kept: dict = {side: {} for side in sides}
    with tempfile.TemporaryDirectory() as tmp:
        for job in jobs:
            reps = 1 if job in ("map", "baseline") and repeats > 3 else repeats
            for r in range(reps):
                for side, python in sides.items():
                    out = Path(tmp) / f"{side}-{job}-{r}.json"
                    res = _child(python, job, out)
                    runs[side][job].append(res["seconds"])
                    if r == 0:
                        kept[side][job] = res
                        npy = Path(str(out) + ".npy")
                        if npy.exists():
                            kept[side][job]["array"] = np.load(npy)
    table = {}
    for job in jobs:
        b, a = statistics.median(runs["before"][job]), statistics.median(runs["after"][job])
        table[job] = {"before_s": b, "after_s": a, "ratio": a / b, "runs": runs}
    same = {}
    if "sweep" in jobs:
        xa, xb = kept["after"]["sweep"]["array"], kept["before"]["sweep"]["array"]
        same["sweep_max_difference"] = float(np.max(np.abs(xa - xb)))
    if "map" in jobs:
        for c in ("motion_u", "motion_v"):
            la, lb = kept["after"]["map"][c], kept["before"]["map"][c]
            same[f"map_{c}_differing_cells"] = sum(x != y for x, y in zip(la, lb, strict=True))
    if "hb" in jobs:
        va, vb = kept["after"]["hb"]["array"], kept["before"]["hb"]["array"]
        same["hb_curve"] = "same length" if va.shape == vb.shape else f"{vb.shape} -> {va.shape}"
        if va.shape == vb.shape:
            same["hb_max_difference"] = float(np.max(np.abs(va - vb)))
    return {"table": table, "same": same, "repeats": repeats}


def lines(res: dict, before: str) -> list[str]:
    t = res["table"]
    out = [
        "# Engine floors: this checkout against the one before (issue 24)",
        "",
        f"Measured by `python benchmarks/floors.py --before {before}`: each figure the median",
        f"of {res['repeats']} fresh processes per side (one for the map and the baseline), the",
        "two sides alternating on the same machine, so the ratio is the figure to read.",
        "",
        "| measure | before (s) | after (s) | after / before |",
        "|---|---|---|---|",
    ]
    names = {
        "sweep": "400-point lambda sweep, compiled DOP853, 300 + 100 periods, one core",
        "baseline": "plain baseline (solve_ivp RK45, hand-written RHS), scaled to 400 points",
        "map": "50 x 50 x 4 regime map with the exponent, two workers",
        "hb": "harmonic balance, 400 frequencies",
    }
    for job, row in t.items():
        out.append(
            f"| {names[job]} | {row['before_s']:.3f} | {row['after_s']:.3f} | {row['ratio']:.3f} |"
        )
    if "sweep" in t and "baseline" in t:
        out += [
            "",
            f"Speed-up of the sweep over the plain baseline: before "
            f"{t['baseline']['before_s'] / t['sweep']['before_s']:.0f}x, after "
            f"{t['baseline']['after_s'] / t['sweep']['after_s']:.0f}x (floor 550x).",
        ]
    out += ["", "Results:", ""]
    out += [f"- {k}: {v}" for k, v in res["same"].items()]
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--before", type=Path, required=True, help="the other checkout")
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--only", nargs="*", choices=JOBS, default=list(JOBS))
    ap.add_argument("--out", type=Path, help="write the Markdown table here")
    args = ap.parse_args(argv)
    if not (args.before / ".venv/bin/python").exists():
        print(f"floors: {args.before}/.venv/bin/python not found; make that venv", file=sys.stderr)
        return 2
    res = measure(args.before, args.repeats, tuple(args.only))
    text = "\n".join(lines(res, str(args.before))) + "\n"
    print(text)
    if args.out:
        args.out.write_text(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
