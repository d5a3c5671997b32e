"""What verdicts on evidence cost: the 400-point sweep and ``gearsym reproduce``, this
checkout against another, in one run.

Run: ``python benchmarks/verdict_cost.py --before DIR [--repeats 3] [--only sweep ...]
[--out FILE]`` where ``DIR`` is another checkout of gearsym with its own virtual environment
in ``DIR/.venv`` (a ``git worktree`` of the commit before issue 27). Each measurement runs
in a fresh process of each checkout, the two alternating, so load on a shared machine
falls on both columns alike; the table gives medians and the ratio after/before.

Floors (issue 27): the 400-point sweep with verdicts at most 2x its time before, and
``gearsym reproduce`` no slower than before (a first run: each side with an empty model
cache, so every derivation and compilation is counted). The sweep is the reference light-load scene
over lambda in [0, 1] at default settings (300 + 100 periods, the exponent, the verdict),
once with independent points and once as a continuation, and the continuation on the
exact dead zone, where chaotic points make the adaptive budget work; the table also
counts the labels and the periods the verdicts took (after: ``periods_run``).
"""

from __future__ import annotations

import argparse
import json
import statistics
import subprocess
import sys
import tempfile
from collections import Counter
from pathlib import Path

CHILD = r"""
import json, sys, time, subprocess, tempfile
import numpy as np
what, out = sys.argv[1], sys.argv[2]
result = {}
if what.startswith("sweep"):
    from gearsym.resolve import load
    from gearsym.solver.sweep.sweep import sweep
    system = load("reference-dead-zone" if what == "sweep-dead-zone" else "reference-light")
    values = np.linspace(0.0, 1.0, 400)
    sweep(system, "lambda", values[:2], continuation=False)  # compile outside the timing
    t = time.perf_counter()
    r = sweep(system, "lambda", values, continuation=(what != "sweep"))
    result["seconds"] = time.perf_counter() - t
    result["labels"] = [p.classification["u"].motion for p in r.points]
    result["periods_run"] = [
        (getattr(p, "verdict", None) or {}).get("periods_run") for p in r.points
    ]
else:
    import os
    args = [sys.executable, "-m", "gearsym", "reproduce", "--quiet", "--out"]
    with tempfile.TemporaryDirectory() as tmp, tempfile.TemporaryDirectory() as cache:
        quick = ["--quick"] if what == "reproduce-quick" else []
        env = dict(os.environ, GEARSYM_CACHE=cache)  # a first run: every model compiled
        t = time.perf_counter()
        subprocess.run([*args, tmp, *quick], check=True, capture_output=True, env=env)
        result["seconds"] = time.perf_counter() - t
json.dump(result, open(out, "w"))
"""
JOBS = ("sweep", "sweep-continued", "sweep-dead-zone", "reproduce-quick", "reproduce")
NAMES = {
    "sweep": "400-point lambda sweep with verdicts, independent points",
    "sweep-continued": "400-point lambda sweep with verdicts, continuation",
    "sweep-dead-zone": "the same continuation on the exact dead zone (reference-dead-zone)",
    "reproduce-quick": "gearsym reproduce --quick",
    "reproduce": "gearsym reproduce",
}


def _child(python: Path, what: str, out: Path) -> dict:
    subprocess.run([str(python), "-c", CHILD, what, str(out)], check=True)
    return json.loads(out.read_text())


def measure(before: Path, repeats: int, jobs) -> dict:
    sides = {"before": before / ".venv/bin/python", "after": Path(sys.executable)}
    seconds: dict = {side: {job: [] for job in jobs} for side in sides}
    kept: dict = {side: {} for side in sides}
    with tempfile.TemporaryDirectory() as tmp:
        for job in jobs:
            reps = 1 if job == "reproduce" else repeats
            for r in range(reps):
                for side, python in sides.items():
                    res = _child(python, job, Path(tmp) / f"{side}-{job}-{r}.json")
                    seconds[side][job].append(res["seconds"])
                    kept[side].setdefault(job, res)
    return {"seconds": seconds, "kept": kept, "repeats": repeats}


def lines(res: dict, before: str) -> list[str]:
    out = [
        "# What verdicts on evidence cost (issue 27)",
        "",
        f"Measured by `python benchmarks/verdict_cost.py --before {before}`: each figure the",
        f"median of {res['repeats']} fresh processes per side (one for the full reproduce), the",
        "two sides alternating on the same machine, so the ratio is the figure to read.",
        "",
        "| measure | before (s) | after (s) | after / before |",
        "|---|---|---|---|",
    ]
    sec = res["seconds"]
    for job in sec["after"]:
        b, a = statistics.median(sec["before"][job]), statistics.median(sec["after"][job])
        out.append(f"| {NAMES[job]} | {b:.2f} | {a:.2f} | {a / b:.2f} |")
    for job in ("sweep", "sweep-continued", "sweep-dead-zone"):
        if job not in res["kept"]["after"]:
            continue
        out += ["", f"Labels of u, {NAMES[job]}:", ""]
        for side in ("before", "after"):
            counts = Counter(res["kept"][side][job]["labels"])
            text = ", ".join(f"{k} {v}" for k, v in counts.most_common())
            out.append(f"- {side}: {text}")
        runs = [p for p in res["kept"]["after"][job]["periods_run"] if p is not None]
        if runs:
            more = sum(p > 400 for p in runs)
            out.append(
                f"- periods the verdicts took (after): median {statistics.median(runs):.0f}, "
                f"largest {max(runs)}; {more} of {len(runs)} points went beyond the 400 "
                "periods of the first run"
            )
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--before", type=Path, required=True, help="the other checkout")
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--only", nargs="*", choices=JOBS, default=list(JOBS))
    ap.add_argument("--out", type=Path, help="write the Markdown table here")
    args = ap.parse_args(argv)
    if not (args.before / ".venv/bin/python").exists():
        print(
            f"verdict_cost: {args.before}/.venv/bin/python not found; make that venv",
            file=sys.stderr,
        )
        return 2
    res = measure(args.before, args.repeats, tuple(args.only))
    text = "\n".join(lines(res, str(args.before))) + "\n"
    print(text)
    if args.out:
        args.out.write_text(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
