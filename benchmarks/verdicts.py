"""The verdict benchmark of issue 27: map verdicts at default settings against long runs.

Cells.  A regime map over lambda by f1 at the default settings of ``regime_map`` (300 +
100 periods, the exponent over the last 200, the verdict's budget of 3,000 periods), from
the forward and backward starts, for each row of :data:`MAPS` (its model, its lambda
range in 21 values, its f1 values; the reference maps run lambda 0 to 1 by f1 0.1, light
load, to 0.5, heavy load): the polynomial backlash in both readings of the loads, the
polynomial with the sensitivity study's 50 um transmission error, the exact dead zone in
both readings, and five maps over the sensitivity study's open values (``OPEN_SPREAD``)
where a coarse scan found the motion types changing (each row says why it was chosen).
Every attractor of a grid point is a candidate cell (its run's start state is recorded);
a cell is on a **border** when its grid point's labels differ from a neighbour's (in
lambda or f1) or the grid point holds attractors of different labels.  All border cells
are taken (evenly thinned if they would fill more than 60 %), then interior cells evenly
spread over the maps, up to :data:`CELLS`.

Default verdict: the map run's own (``RunRecord.verdict``: motion, periods run, why).
Reference: ``_verdicts_reference.reference_label``, a 10,000-period run from the same
start state, its last 5,000 periods classified by code of its own.  A **wrong label** is
a default label that is neither the reference's nor ``undetermined``; cells whose
reference is ``unresolved`` are listed and not counted.  The floor (issue 27): no wrong
label, ``undetermined`` at most 10 %.

Writes ``docs/verdicts.md`` (``_verdicts_report.py``: the maps, the confusion table, the
cost, every wrong, undetermined or unresolved cell with both verdicts' evidence, and the
undetermined candidates) and ``docs/verdicts.json`` (``--quick``: 20 cells of smaller
maps, ``verdicts-quick.*``), stamped with the checkout's commit.  Run from a checkout:
``python benchmarks/verdicts.py`` (``--workers`` at most 2; ``--store DIR`` keeps the
maps' runs to resume: a store made on another commit of the engine holds its verdicts).
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path
from typing import NamedTuple

import numpy as np
from gearsym.benchmarks._output import checkout_docs, output_folder, run_script
from gearsym.benchmarks._verdicts_report import default_label as _label
from gearsym.benchmarks._verdicts_report import markdown

__all__ = ["MAPS", "MapRow", "main", "pick", "run_maps", "summarise"]


class MapRow(NamedTuple):
    """One map of the benchmark: its model (a scene and open values), its lambda range
    (``POINTS`` values from ``lam[0]`` to ``lam[1]``), its f1 values, and why it is here."""

    name: str
    scene: str
    open_values: dict
    lam: tuple = (0.0, 1.0)
    f1: tuple = (0.1, 0.2, 0.3, 0.4, 0.5)
    why: str = "a reference map"


LOW_LAMBDA = (0.0, 0.25)
HEAVY = (0.6, 0.7, 0.8)  # beyond the reference maps' heavy load, f1 0.5
# The last five rows were chosen by a coarse scan (lambda 0 to 1 in 11 values by three or
# four f1, then lambda 0 to 0.2 in 9 values by f1 0.1 to 0.5, both starts, default
# settings) over the open values of app/studies/sensitivity.py: te_amplitude_um 20,
# te_phase_deg_qg 90 and 180, flywheel_inertia_kg_m2 1 and 100, layout_angle_deg 0 and
# 60, stiffness_harmonic_scale 2 and f1 0.5 to 0.8, on the polynomial and the dead zone.
# On the polynomial every one of them is period-1 over the whole map (one period-3 at
# phase 90), so only its heavy-load range with the 50 um error, where period doubling
# moves with f1, is kept; on the dead zone the motion types change below lambda 0.2, so
# those maps zoom there.  No verdict of the scan was quasi-periodic.
MAPS = (
    MapRow("polynomial, q braking", "reference-light", {}),
    MapRow("polynomial, both driving", "reference-light-both-driving", {}),
    MapRow("polynomial, q braking, TE 50 µm", "reference-light", {"te_amplitude_um": 50.0}),
    MapRow("dead zone, q braking", "reference-dead-zone", {}),
    MapRow("dead zone, both driving", "reference-dead-zone", {"load_reading": "both-driving"}),
    MapRow(
        "dead zone, q braking, TE phase 90°",
        "reference-dead-zone",
        {"te_phase_deg_qg": 90.0},
        LOW_LAMBDA,
        why="chaos, period 1 to 6 and an undetermined verdict (exponent near zero at f1 0.5, "
        "lambda 0) side by side below lambda 0.2",
    ),
    MapRow(
        "dead zone, q braking, flywheel 100 kg m²",
        "reference-dead-zone",
        {"flywheel_inertia_kg_m2": 100.0},
        LOW_LAMBDA,
        why="the widest chaotic region of the scan, left through period 4 and 2 and with "
        "chaos beside period 2 at one grid point",
    ),
    MapRow(
        "dead zone, q braking, harmonics ×2",
        "reference-dead-zone",
        {"stiffness_harmonic_scale": 2.0},
        LOW_LAMBDA,
        why="the most period multiples of the scan (2, 3, 4, 5, 6, 8) between chaotic "
        "points: periodic windows",
    ),
    MapRow(
        "dead zone, q braking, TE 20 µm",
        "reference-dead-zone",
        {"te_amplitude_um": 20.0},
        why="period-1 everywhere but one undetermined attractor beside a period-1 one at "
        "f1 0.5, lambda 0.4: a border far from low lambda",
    ),
    MapRow(
        "polynomial, q braking, TE 50 µm, heavy",
        "reference-light",
        {"te_amplitude_um": 50.0},
        f1=HEAVY,
        why="the heavy-load f1 range: period 1 to 2 to 4 and back, the doubling moving "
        "to lower lambda as f1 grows",
    ),
)
POINTS = {"full": 21, "quick": 6}
CELLS = {"full": 200, "quick": 20}
BORDER_SHARE = 0.6


def _axes(row: MapRow, quick: bool) -> tuple[np.ndarray, np.ndarray]:
    """The row's lambda values and f1 values (quick: 6 lambda, the first and last f1)."""
    lam = np.round(np.linspace(*row.lam, POINTS["quick" if quick else "full"]), 10)
    return lam, np.array(row.f1[:: len(row.f1) - 1] if quick else row.f1, float)


def run_maps(quick: bool, workers: int, store: Path | None) -> tuple[list[dict], dict]:
    """Every map of :data:`MAPS`: its candidate cells (one per attractor of a grid
    point) with the default verdict, start state and border flag; and each map's
    seconds."""
    from gearsym.resolve import load
    from gearsym.solver.sweep.atlas import regime_map

    cells, seconds = [], {}
    for row in MAPS:
        name, scene, open_values = row.name, row.scene, row.open_values
        lam, f1 = _axes(row, quick)
        started = time.perf_counter()
        slug = "".join(ch if ch.isalnum() else "-" for ch in name)
        m = regime_map(
            load(scene, **open_values),
            ("lambda", lam),
            ("f1", f1),
            initial_states=2,
            workers=workers,
            store=None if store is None else store / f"{slug}-{lam.size}",
        )
        seconds[name] = time.perf_counter() - started
        print(f"map {name}: {seconds[name]:.0f} s", file=sys.stderr)
        labels = [[{_label(a.run.verdict) for a in c.attractors} for c in col] for col in m.cells]
        for ix, col in enumerate(m.cells):
            for iy, cell in enumerate(col):
                near = [(ix + dx, iy + dy) for dx, dy in ((1, 0), (-1, 0), (0, 1), (0, -1))]
                near = [(i, k) for i, k in near if 0 <= i < len(lam) and 0 <= k < len(f1)]
                here = labels[ix][iy]
                border = len(here) > 1 or any(labels[i][k] != here for i, k in near)
                for a in cell.attractors:
                    r = a.run
                    cells.append(
                        {
                            "map": name,
                            "scene": scene,
                            "open_values": open_values,
                            "lambda": cell.x,
                            "f1": cell.y,
                            "start": r.start,
                            "starts": list(a.starts),
                            "x0": [float(v) for v in r.x0],
                            "border": border,
                            "status": r.status,
                            "default": {k: v for k, v in r.verdict.items() if k != "windows"},
                        }
                    )
    return cells, seconds


def _spread(items: list, k: int) -> list:
    """``k`` of ``items``, evenly spaced (all when there are no more than k)."""
    if len(items) <= k:
        return list(items)
    return [items[int(i)] for i in np.linspace(0, len(items) - 1, k).round()]


def pick(cells: list[dict], total: int) -> list[dict]:
    """Border cells first (at most ``BORDER_SHARE`` of ``total``, evenly over the maps),
    then interior cells evenly spread over the maps, up to ``total``."""
    names = list(dict.fromkeys(c["map"] for c in cells))

    def share(pool: list[dict], k: int) -> list[dict]:
        per = {n: [c for c in pool if c["map"] == n] for n in names}
        out, left = [], k
        for i, n in enumerate(sorted(names, key=lambda n: len(per[n]))):
            take = _spread(per[n], left // (len(names) - i))
            out += take
            left -= len(take)
        return out

    border = share([c for c in cells if c["border"]], int(BORDER_SHARE * total))
    rest = share([c for c in cells if not c["border"]], total - len(border))
    return sorted(border + rest, key=lambda c: (names.index(c["map"]), c["f1"], c["lambda"]))


_SYSTEMS: dict = {}


def _reference(cell: dict) -> dict:
    """Worker: the reference label of one cell (see ``_verdicts_reference``)."""
    from gearsym.benchmarks._verdicts_reference import reference_label
    from gearsym.resolve import load

    key = (cell["scene"], tuple(sorted(cell["open_values"].items())))
    if key not in _SYSTEMS:
        _SYSTEMS[key] = load(cell["scene"], **cell["open_values"])
    system = _SYSTEMS[key].with_values(**{"lambda": cell["lambda"], "f1": cell["f1"]})
    started = time.perf_counter()
    ref = reference_label(system, np.array(cell["x0"]))
    return ref | {"seconds": time.perf_counter() - started}


def summarise(cells: list[dict]) -> dict:
    """The confusion table (reference label -> default label -> count), the wrong and
    undetermined cells, the undetermined share and the median periods run per label."""
    confusion: dict = {}
    for c in cells:
        row = confusion.setdefault(c["reference"]["label"], {})
        row[_label(c["default"])] = row.get(_label(c["default"]), 0) + 1
    for c in cells:
        ref, got = c["reference"]["label"], _label(c["default"])
        c["wrong"] = ref != "unresolved" and got not in (ref, "undetermined")
    runs: dict = {}
    for c in cells:
        if c["default"].get("periods_run") is not None:
            runs.setdefault(_label(c["default"]), []).append(c["default"]["periods_run"])
    undetermined = sum(_label(c["default"]) == "undetermined" for c in cells)
    return {
        "cells": len(cells),
        "border_cells": sum(c["border"] for c in cells),
        "wrong": sum(c["wrong"] for c in cells),
        "undetermined": undetermined,
        "undetermined_share": undetermined / max(len(cells), 1),
        "unresolved_references": sum(c["reference"]["label"] == "unresolved" for c in cells),
        "confusion": confusion,
        "median_periods_run": {k: float(np.median(v)) for k, v in sorted(runs.items())},
    }


def _candidates(candidates: list[dict]) -> dict:
    """The default labels of every candidate (judged cells or not): counts, and the
    undetermined ones with their reason (no reference run: not in the floors)."""
    counts: dict = {}
    for c in candidates:
        counts[_label(c["default"])] = counts.get(_label(c["default"]), 0) + 1
    keys = ("map", "lambda", "f1", "start")
    undetermined = [
        {k: c[k] for k in keys} | {"why": c["default"].get("why")}
        for c in candidates
        if _label(c["default"]) == "undetermined"
    ]
    return {"count": len(candidates), "labels": counts, "undetermined": undetermined}


def _engine() -> str:
    """The last commit that changed ``solver/`` (the engine whose verdicts these are),
    marked when ``solver/`` has local changes; taken before the first run."""
    import subprocess

    from gearsym.derive.build import project_root

    def git(*a: str) -> str:
        run = subprocess.run(["git", *a], cwd=project_root(), capture_output=True, text=True)
        return run.stdout.strip() if run.returncode == 0 else ""

    head = git("log", "-1", "--format=%h", "--", "solver") or "unknown"
    return head + (" + local changes in solver/" if git("status", "--porcelain", "solver") else "")


def _plain(x):
    if isinstance(x, np.ndarray):
        return x.tolist()
    if isinstance(x, np.generic):
        return x.item()
    raise TypeError(f"not JSON: {type(x).__name__}")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="20 cells of smaller maps")
    ap.add_argument("--workers", type=int, default=2, choices=(1, 2), help="processes (1 or 2)")
    ap.add_argument("--store", type=Path, help="keep the maps' runs here (a rerun resumes)")
    ap.add_argument("--out", type=Path, help="output folder (default: the checkout's docs/)")
    args = ap.parse_args(argv)
    stem = "verdicts-quick" if args.quick else "verdicts"
    names = (f"{stem}.md", f"{stem}.json")
    out = output_folder(args.out or checkout_docs(), names)
    command = "python benchmarks/verdicts.py" + (" --quick" if args.quick else "")
    started, engine = time.perf_counter(), _engine()
    candidates, map_seconds = run_maps(args.quick, args.workers, args.store)
    cells = pick(candidates, CELLS["quick" if args.quick else "full"])
    print(f"{len(cells)} cells of {len(candidates)}; reference runs", file=sys.stderr)
    from gearsym.solver.executor import map_tasks

    executor = "processes" if args.workers > 1 else "serial"
    refs = map_tasks(_reference, cells, executor=executor, workers=args.workers)
    for c, r in zip(cells, refs, strict=True):
        c["reference"] = r
    summary = summarise(cells)
    wall = time.perf_counter() - started
    seconds = [c["reference"]["seconds"] for c in cells]
    summary["maps"] = {}
    for row in MAPS:
        lam, f1 = _axes(row, args.quick)
        summary["maps"][row.name] = {
            "lambda": lam,
            "f1": f1,
            "why": row.why,
            "candidates": sum(c["map"] == row.name for c in candidates),
            "cells": sum(c["map"] == row.name for c in cells),
            "seconds": map_seconds[row.name],
        }
    summary["cost"] = {
        "maps_seconds": sum(map_seconds.values()),
        "reference_seconds": float(np.sum(seconds)),
        "reference_median_seconds": float(np.median(seconds)),
        "reference_max_seconds": float(np.max(seconds)),
        "workers": args.workers,
        "wall_seconds": wall,
    }
    summary["candidates"] = _candidates(candidates)
    summary["engine"] = engine
    text = markdown(summary, cells, command, wall)
    (out / names[0]).write_text(text, encoding="utf-8")
    doc = {"command": command, "wall_seconds": wall, "summary": summary, "cells": cells}
    (out / names[1]).write_text(json.dumps(doc, indent=1, default=_plain), encoding="utf-8")
    print(text)
    return 0


if __name__ == "__main__":
    run_script(main)
