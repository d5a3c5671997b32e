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

__all__ = ["LONG_BUDGET", "lengthen", "lengthen_sweeps", "periods_run"]

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
