"""The long budget for the runs that carry a claim of the report.

A verdict of chaos or of a torus settles on its last windows; a chaotic transient can
outlast the default budget (``settle.BUDGET``, 3,000 periods).  Every run a "reproduced"
claim rests on is therefore continued **from where it ended** with the border budget of
the sweeps and maps (``borders.BORDER_BUDGET``, 8,000 periods, a chaotic or quasi-periodic
label then needing that many), by the one engine that re-examines border runs
(``gearsym.solver.sweep.borders.reexamine``).  A run on a confirmed attracting periodic
orbit is not run again: a longer run cannot leave it.
"""

from __future__ import annotations

from dataclasses import replace

from gearsym.solver.analysis.point import classification_tolerance
from gearsym.solver.sweep import map_tasks
from gearsym.solver.sweep.borders import BORDER_BUDGET, Look, needs_look, run_look

__all__ = [
    "LONG_BUDGET",
    "lengthen",
    "lengthen_carriers",
    "lengthen_claims",
    "lengthen_sweeps",
    "periods_run",
]

LONG_BUDGET = BORDER_BUDGET  # periods a claim-carrying run's verdict may take


def _long_enough(r) -> bool:
    """Already continued with at least the long budget (a border run of its sweep)."""
    seen = (r.verdict or {}).get("reexamined") or {}
    return int(seen.get("budget") or 0) >= LONG_BUDGET


def lengthen(
    pairs, settings: dict, *, executor: str, workers: int | None, progress=None, memo=None
) -> list:
    """Each run of ``pairs`` continued with the long budget where it needs it.

    Parameters
    ----------
    pairs : list of (System, RunRecord)
        The model at the run's parameter values and the run.
    settings : dict
        ``method``, ``rtol``, ``atol`` of the runs.
    progress : callable, optional
        ``progress(total)`` -> a :class:`~gearsym.solver.sweep.progress.Progress` of the
        runs continued (called once, before they start).
    memo : ResultStore, optional
        Where runs continued before are loaded from (:mod:`gearsym.studies.memo`).

    Returns
    -------
    list of RunRecord
        In the order of ``pairs``: re-examined (``verdict['reexamined']``) where the run
        was not on a confirmed periodic orbit and not yet run that long, else unchanged.
    """
    options = {
        "tol": classification_tolerance(settings["method"], settings["rtol"]),
        "method": settings["method"],
        "rtol": settings["rtol"],
        "atol": settings["atol"],
        "budget": LONG_BUDGET,
    }
    out = [r for _, r in pairs]
    todo = [
        k
        for k, (_, r) in enumerate(pairs)
        if needs_look(r) and r.x_final is not None and not _long_enough(r)
    ]
    looks = [
        Look(str(pairs[k][0].module.__file__), tuple(map(float, pairs[k][0].p)), out[k], options)
        for k in todo
    ]
    bar = progress(len(looks)) if progress is not None else None
    if looks:
        run = map_tasks if memo is None else memo.map
        done = run(run_look, looks, executor=executor, workers=workers, on_result=bar)
        for k, r in zip(todo, done, strict=True):
            out[k] = r
    return out


def periods_run(records) -> str:
    """'run 400 periods' or 'run 400 to 8,000 periods': the verdicts' ``periods_run``."""
    n = sorted(int((r.verdict or {}).get("periods_run") or 0) for r in records)
    if not n:
        return "no run"
    if n[0] == n[-1]:
        return f"run {n[0]:,} periods"
    return f"run {n[0]:,} to {n[-1]:,} periods"


def lengthen_sweeps(
    items, select, settings: dict, *, executor: str, workers: int | None, progress=None, memo=None
):
    """Sweeps with the runs ``select`` picks continued with the long budget (one batch
    over every sweep, so the workers share it).

    Parameters
    ----------
    items : list of (SweepResult, System)
        Each sweep and its model (at the sweep's base values).
    select : callable (SweepResult, value, RunRecord) -> bool
        Whether a run carries a claim.
    progress, memo : optional
        As for :func:`lengthen`.

    Returns
    -------
    list of SweepResult
        In the order of ``items``; a sweep with a run continued has its points replaced.
    """
    pairs, where = [], []
    for j, (sw, system) in enumerate(items):
        for k, (v, r) in enumerate(zip(sw.values, sw.points, strict=True)):
            if select(sw, float(v), r):
                pairs.append((system.with_values(**{sw.parameter: float(v)}), r))
                where.append((j, k))
    done = lengthen(
        pairs, settings, executor=executor, workers=workers, progress=progress, memo=memo
    )
    points = [list(sw.points) for sw, _ in items]
    changed = set()
    for (j, k), r, (_, before) in zip(where, done, pairs, strict=True):
        if r is not before:
            points[j][k] = r
            changed.add(j)
    return [
        replace(sw, points=points[j], texts=None) if j in changed else sw
        for j, (sw, _) in enumerate(items)
    ]


def lengthen_claims(
    got: dict, groups: dict, settings, *, executor, workers, progress, memo
) -> dict:
    """The sweeps with every run a claim may rest on continued with the long budget:
    the forward case sweeps' non-periodic runs in the study's low-lambda ranges (u
    quasi-periodic up to 0.57 light, 0.13 heavy; v chaotic up to 0.3) and the maps'
    non-periodic runs (the trend of Min(v) over chaotic points).  One batch for all, so
    that the workers share it."""
    low = {0.1: 0.57, 0.5: 0.3}  # f1 -> the largest lambda of a low-lambda claim
    names = ("cases", "dead cases", "maps", "dead maps")
    on_maps = {id(sw) for n in names[2:] for sw in got[n]}

    def select(sw, value, r):
        if id(sw) in on_maps:
            return True
        f1 = float(sw.base_values.get("f1", 0.1 if "light" in sw.model else 0.5))
        return sw.direction == "forward" and value <= low.get(f1, 0.57) + 1e-9

    items = [(sw, job.system) for n in names for sw, job in zip(got[n], groups[n], strict=True)]
    longer = iter(
        lengthen_sweeps(
            items,
            select,
            settings,
            executor=executor,
            workers=workers,
            progress=progress,
            memo=memo,
        )
    )
    out = dict(got)
    for n in names:
        out[n] = [next(longer) for _ in got[n]]
    return out


def lengthen_carriers(m, findings, resolve, settings, executor, workers, matches):
    """The map ``m`` with every attractor that carries a finding (inside the finding's lambda
    range, with its motion) continued with the long budget (``long_runs``), and per
    finding the runs that still carry it: (count, the periods they were run).
    ``matches(motion, test)``: whether a run's motion carries a finding's test."""

    def carries(run, coord, test, lo, hi):
        return lo <= run.values["lambda"] <= hi and run.ok and matches(run.motion(coord), test)

    where = [
        (ix, iy, k)
        for ix, column in enumerate(m.cells)
        for iy, cell in enumerate(column)
        for k, a in enumerate(cell.attractors)
        if any(carries(a.run, c, t, lo, hi) for _, c, t, (lo, hi) in findings)
    ]
    runs = [m.cells[ix][iy].attractors[k].run for ix, iy, k in where]
    pairs = [(resolve(dict(r.values)), r) for r in runs]
    longer = lengthen(pairs, settings, executor=executor, workers=workers)
    longer = dict(zip(where, longer, strict=True))
    cells = tuple(
        tuple(
            replace(
                cell,
                attractors=tuple(
                    replace(a, run=longer.get((ix, iy, k), a.run))
                    for k, a in enumerate(cell.attractors)
                ),
            )
            for iy, cell in enumerate(column)
        )
        for ix, column in enumerate(m.cells)
    )
    m = replace(m, cells=cells)
    carriers = {}
    for finding, coord, test, (lo, hi) in findings:
        held = [r for r in longer.values() if carries(r, coord, test, lo, hi)]
        carriers[finding] = (len(held), periods_run(held))
    return m, carriers
