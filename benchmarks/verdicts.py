"""The verdict benchmark of issue 27: map verdicts at default settings against long runs.

Cells.  A regime map over lambda (0 to 1) by f1 (0.1, light load, to 0.5, heavy load) at
the default settings of ``regime_map`` (300 + 100 periods, the exponent over the last 200,
the verdict's budget of 3,000 periods), from the forward and backward starts, for each
model of :data:`MAPS`: the polynomial backlash in both readings of the loads, the
polynomial with the sensitivity study's 50 um transmission error, and the exact dead
zone in both readings.  Every attractor of a grid point is a candidate cell (its run's
start state is recorded); a cell is on a **border** when its grid point's labels differ
from a neighbour's (in lambda or f1) or the grid point holds attractors of different
labels.  All border cells are taken (evenly thinned if they would fill more than 60 %),
then interior cells evenly spread over the maps, up to :data:`CELLS`.

Default verdict: the map run's own (``RunRecord.verdict``: motion, periods run, why).
Reference: ``_verdicts_reference.reference_label``, a 10,000-period run from the same
start state, its last 5,000 periods classified by code of its own.  A **wrong label** is
a default label that is neither the reference's nor ``undetermined``; cells whose
reference is ``unresolved`` are listed and not counted.  The floor (issue 27): no wrong
label, ``undetermined`` at most 10 %.

Writes ``docs/verdicts.md`` and ``docs/verdicts.json`` (``--quick``: 20 cells of smaller
maps, ``verdicts-quick.*``).  Run from a checkout: ``python benchmarks/verdicts.py``
(``--workers`` at most 2; ``--store DIR`` keeps the maps' runs to resume).
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np
from gearsym.benchmarks._output import checkout_docs, output_folder, run_script
from gearsym.benchmarks._verdicts_reference import K_CHAOS, QP_BAND, REPEAT

__all__ = ["MAPS", "main", "pick", "run_maps", "summarise"]

# (name, scene, open values): the reference maps of the benchmark
MAPS = (
    ("polynomial, q braking", "reference-light", {}),
    ("polynomial, both driving", "reference-light-both-driving", {}),
    ("polynomial, q braking, TE 50 µm", "reference-light", {"te_amplitude_um": 50.0}),
    ("dead zone, q braking", "reference-dead-zone", {}),
    ("dead zone, both driving", "reference-dead-zone", {"load_reading": "both-driving"}),
)
GRID = {"full": (21, (0.1, 0.2, 0.3, 0.4, 0.5)), "quick": (6, (0.1, 0.5))}
CELLS = {"full": 120, "quick": 20}
BORDER_SHARE = 0.6


def _label(verdict: dict) -> str:
    return verdict.get("motion") or "undetermined"


def run_maps(quick: bool, workers: int, store: Path | None) -> list[dict]:
    """Every map of :data:`MAPS`: its candidate cells (one per attractor of a grid
    point) with the default verdict, start state and border flag."""
    from gearsym.resolve import load
    from gearsym.solver.sweep.atlas import regime_map

    points, f1 = GRID["quick" if quick else "full"]
    lam = np.round(np.linspace(0.0, 1.0, points), 10)
    cells = []
    for name, scene, open_values in MAPS:
        started = time.perf_counter()
        slug = "".join(ch if ch.isalnum() else "-" for ch in name)
        m = regime_map(
            load(scene, **open_values),
            ("lambda", lam),
            ("f1", np.array(f1)),
            initial_states=2,
            workers=workers,
            store=None if store is None else store / f"{slug}-{points}",
        )
        print(f"map {name}: {time.perf_counter() - started:.0f} s", file=sys.stderr)
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
    return cells


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


def _order(label: str) -> tuple:
    if label.startswith("period-"):
        return (0, int(label.split("-")[1]))
    rank = ("quasi-periodic", "chaotic", "divergent", "undetermined", "unresolved")
    return (1, rank.index(label) if label in rank else len(rank))


def _evidence(ref: dict) -> str:
    """The reference's evidence in one line."""
    parts = []
    per = ref.get("periodic")
    if per and per.get("ok"):
        mu = per["shooting"]["largest_multiplier"]
        conv = ", converging" if per["converging"] else ""
        parts.append(f"repeats after {per['n']} (gap {per['repeat_gap']:.1e}{conv}), |μ| {mu:.4f}")
        parts.append(f"settled by period {ref.get('settled_by_period')}")
    if "exponent" in ref:
        e = ref["exponent"]
        parts.append(f"λ {e['lambda']:.2e} ± {e['uncertainty']:.1e}")
    if "zero_one" in ref:
        parts.append(f"K {ref['zero_one']['K']:.2f}")
    if "curve" in ref:
        parts.append(f"curve {ref['curve']['agreeing']:.2f}")
    if "why" in ref:
        parts.append(ref["why"])
    return "; ".join(parts)


def _markdown(summary: dict, cells: list[dict], command: str, wall: float, quick: bool) -> str:
    s = summary
    refs = sorted(s["confusion"], key=_order)
    cols = sorted(
        {k for row in s["confusion"].values() for k in row} | {"undetermined"}, key=_order
    )
    points, f1 = GRID["quick" if quick else "full"]
    lines = [
        "# Verdict benchmark: map verdicts against 10,000-period reference runs",
        "",
        f"Written by `{command}` in {wall / 60:.1f} min (issue 27, Floors). "
        f"Maps: λ 0 to 1 in {points} values by f1 {', '.join(map(str, f1))} (0.1 light, "
        "0.5 heavy load), forward and backward starts, `regime_map`'s default settings "
        "(300 + 100 periods, exponent over 200, verdict budget 3,000 periods), one per "
        f"model: {'; '.join(n for n, _, _ in MAPS)}. Cells: {s['cells']} attractors of the "
        f"maps, {s['border_cells']} on borders (labels differ from a neighbour's, or "
        "coexisting attractors with different labels), the rest spread over the interiors. "
        "Reference: a 10,000-period run from the cell's start state (DOP853, rtol 1e-10), "
        "its last 5,000 periods classified by the benchmark's own code "
        f"(`benchmarks/_verdicts_reference.py`: repetition within {REPEAT:g} of the extent "
        "and `shoot` with |μ| < 1 at the minimal period; chaos: λ − U > 0 over the tail "
        f"and its own 0–1 test K ≥ {K_CHAOS}; a torus: |λ| + U ≤ {QP_BAND:g} and a closed "
        "curve the map rotates).",
        "",
        f"**Wrong labels: {s['wrong']}** (floor: 0). **Undetermined: {s['undetermined']} of "
        f"{s['cells']} = {100 * s['undetermined_share']:.1f} %** (floor: at most 10 %). "
        f"Reference unresolved (not counted): {s['unresolved_references']}.",
        "",
        "## Confusion table (rows: reference, columns: default verdict)",
        "",
        "| reference \\ default | " + " | ".join(cols) + " |",
        "|---|" + "---:|" * len(cols),
    ]
    for r in refs:
        row = s["confusion"][r]
        lines.append(f"| {r} | " + " | ".join(str(row.get(k, "")) for k in cols) + " |")
    lines += ["", "Median periods run by the default verdict, per label: "]
    lines[-1] += ", ".join(f"{k} {v:.0f}" for k, v in s["median_periods_run"].items()) + "."
    listed = [c for c in cells if c["wrong"] or _label(c["default"]) == "undetermined"]
    listed += [c for c in cells if c["reference"]["label"] == "unresolved" and c not in listed]
    lines += [
        "",
        "## Wrong, undetermined and unresolved cells",
        "",
        "| map | λ | f1 | start | default (periods) | default's why | reference | evidence |",
        "|---|---:|---:|---|---|---|---|---|",
    ]
    for c in listed:
        d = c["default"]
        mark = "**wrong** " if c["wrong"] else ""
        why = (d.get("why") or "").replace("|", "/")
        lines.append(
            f"| {c['map']} | {c['lambda']:g} | {c['f1']:g} | {c['start']} | {mark}"
            f"{_label(d)} ({d.get('periods_run')}) | {why} | {c['reference']['label']} | "
            f"{_evidence(c['reference']).replace('|', '/')} |"
        )
    if not listed:
        lines.append("| (none) | | | | | | | |")
    lines += ["", "Every cell, its start state and both verdicts' evidence: `verdicts.json`."]
    return "\n".join(lines) + "\n"


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
    started = time.perf_counter()
    candidates = run_maps(args.quick, args.workers, args.store)
    cells = pick(candidates, CELLS["quick" if args.quick else "full"])
    print(f"{len(cells)} cells of {len(candidates)}; reference runs", file=sys.stderr)
    from gearsym.solver.executor import map_tasks

    executor = "processes" if args.workers > 1 else "serial"
    refs = map_tasks(_reference, cells, executor=executor, workers=args.workers)
    for c, r in zip(cells, refs, strict=True):
        c["reference"] = r
    summary = summarise(cells)
    wall = time.perf_counter() - started
    text = _markdown(summary, cells, command, wall, args.quick)
    (out / names[0]).write_text(text, encoding="utf-8")
    doc = {"command": command, "wall_seconds": wall, "summary": summary, "cells": cells}
    (out / names[1]).write_text(json.dumps(doc, indent=1, default=_plain), encoding="utf-8")
    print(text)
    return 0


if __name__ == "__main__":
    run_script(main)
