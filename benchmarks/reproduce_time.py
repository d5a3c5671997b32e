"""How long ``gearsym reproduce`` takes: a first run on an empty cache and a repeated run.

Run: ``python benchmarks/reproduce_time.py [--only quick|full] [--repeats 3] [--out FILE]``
(default: both resolutions, 3 repeats, ``docs/reproduce-time.md`` of the checkout).  Each
repeat makes a new empty model cache (``GEARSYM_CACHE``) and runs, each in a fresh process
and a fresh output folder: the first run (every model derived and compiled) and then the
repeated run (the same cache: every model compiled, every unit of work in its result
store, ``gearsym.studies.memo``; a new output folder, so no sweep of the first run's
folder is resumed).  The table gives the median over the repeats of the wall time of
the whole process, and per stage (``gearsym.studies.reproduce.STAGES``) the median of the
seconds each took.  Floors (issue 25, point 7): the full reproduce at most 90 s on a first
run and 30 s on a repeated run, on 2 cores of a quiet machine.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from gearsym.benchmarks._output import checkout_docs, output_folder, run_script
from gearsym.studies.reproduce import verdict_words

# The child: one reproduce in this process, its stage times as JSON (wall time is taken
# by the parent, interpreter start and imports included).
CHILD = r"""
import json, sys
from pathlib import Path
from gearsym.studies.reproduce import reproduce
out, quick, result = Path(sys.argv[1]), sys.argv[2] == "quick", Path(sys.argv[3])
done = reproduce(out, quick=quick, progress=False)
said = {"stages": done.stages, "verdicts": done.verdicts, "stored": done.stored}
result.write_text(json.dumps(said))
"""
FLOORS = {"full": (90.0, 30.0)}  # first, repeated (s), issue 25 point 7
RUNS = ("first", "repeated")


def _one(variant: str, cache: Path, folder: Path) -> dict:
    """One reproduce in a fresh process: wall seconds, stage seconds, verdict counts."""
    result = folder / "result.json"
    env = dict(os.environ, GEARSYM_CACHE=str(cache))
    started = time.perf_counter()
    subprocess.run(
        [sys.executable, "-c", CHILD, str(folder / "out"), variant, str(result)],
        check=True,
        env=env,
    )
    seconds = time.perf_counter() - started
    data = json.loads(result.read_text())
    return {"seconds": seconds, "stages": [tuple(s) for s in data["stages"]], **data}


def measure(variant: str, repeats: int) -> dict:
    """``{"first": [run, ...], "repeated": [run, ...]}``, ``repeats`` of each."""
    out: dict = {run: [] for run in RUNS}
    for r in range(repeats):
        with tempfile.TemporaryDirectory(prefix="reproduce-time-") as tmp:
            cache = Path(tmp) / "cache"
            cache.mkdir()
            for run in RUNS:
                folder = Path(tmp) / run
                folder.mkdir()
                out[run].append(_one(variant, cache, folder))
                done = out[run][-1]["seconds"]
                print(f"{variant} {run} run {r + 1} of {repeats}: {done:.1f} s", file=sys.stderr)
    return out


def table(results: dict, when: str, machine: str) -> str:
    """The Markdown page: totals against the floors, then the stages of each variant."""
    lines = [
        "# How long `gearsym reproduce` takes (issue 25, point 7)",
        "",
        "Measured by `python benchmarks/reproduce_time.py`: each repeat a new empty model "
        "cache; a first run (every model derived and compiled), then a repeated run (same "
        "cache, new output folder); each a fresh process. Medians over the repeats.",
        "",
        f"{when}; {machine}.",
        "",
        "| reproduce | repeats | first run (s) | repeated run (s) | floor (first / repeated) |",
        "|---|---|---|---|---|",
    ]
    for variant, runs in results.items():
        first, again = (statistics.median(r["seconds"] for r in runs[k]) for k in RUNS)
        floor = FLOORS.get(variant)
        said = "—" if floor is None else f"{floor[0]:.0f} s / {floor[1]:.0f} s"
        if floor is not None:
            said += f": {'met' if first <= floor[0] else 'not met'} / "
            said += "met" if again <= floor[1] else "not met"
        name = "`gearsym reproduce" + (" --quick`" if variant == "quick" else "`")
        lines.append(f"| {name} | {len(runs['first'])} | {first:.1f} | {again:.1f} | {said} |")
    for variant, runs in results.items():
        lines += ["", f"Stages of `{variant}` (median seconds):", ""]
        lines += ["| stage | first run | repeated run |", "|---|---|---|"]
        names = [name for name, _ in runs["first"][0]["stages"]]
        for k, name in enumerate(names):
            cells = [statistics.median(r["stages"][k][1] for r in runs[run]) for run in RUNS]
            lines.append(f"| {name} | {cells[0]:.1f} | {cells[1]:.1f} |")
        for run in RUNS:
            stored = runs[run][0].get("stored")
            if stored:
                lines += ["", f"Result store, {run} run: {stored}."]
        verdicts = runs["first"][0]["verdicts"]
        said = "; ".join(f"{model}: {verdict_words(c)}" for model, c in verdicts.items())
        lines += ["", f"Verdicts of the study's findings (first run): {said}."]
    return "\n".join(lines) + "\n"


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument(
        "--only", choices=("quick", "full"), help="one resolution (default: quick and full)"
    )
    ap.add_argument("--repeats", type=int, default=3, help="repeats per run (default 3)")
    ap.add_argument("--out", type=Path, help="the page (default docs/reproduce-time.md)")
    args = ap.parse_args(argv)
    if args.repeats < 1:
        ap.error(f"--repeats {args.repeats}: give 1 or more")
    out = args.out or checkout_docs() / "reproduce-time.md"
    output_folder(out.parent, (out.name,))  # before the runs: an OutputError is one line
    variants = [args.only] if args.only else ["quick", "full"]
    load = os.getloadavg()[0] if hasattr(os, "getloadavg") else float("nan")
    results = {v: measure(v, args.repeats) for v in variants}
    machine = (
        f"{os.cpu_count()} cores, {platform.machine()}, Python {platform.python_version()}, "
        f"load average {load:.2f} at the start"
    )
    out.write_text(table(results, time.strftime("%Y-%m-%d"), machine), encoding="utf-8")
    print(f"wrote {out}")
    return 0


if __name__ == "__main__":
    run_script(main)
