"""Sweeps and maps look again where neighbours disagree.

A verdict settles on the evidence of its last windows; near a bifurcation (a border
between two kinds of motion) that evidence is weakest and a chaotic transient longest.
So after a sweep or a map, every run whose motion differs from a neighbour's (the next
value of a sweep; the four grid neighbours of a map) and whose verdict is not a
confirmed periodic orbit is continued **from where it ended** with the long budget
``BORDER_BUDGET``, a chaotic or quasi-periodic label needing that many periods
(``settle(min_periods=...)``), and the shooting check at every window.  A run already on an
attracting periodic orbit (the shooting check's multipliers inside the unit circle) is
not run again: a longer run cannot leave it.  Re-examined runs say so in their verdict
(``reexamined``: the periods before and the budget).
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from ..analysis.record import Extremes, RunRecord
from ..analysis.settle import BUDGET, per_coordinate, settle, settle_many
from ..contract import Contract, load_generated
from ..system import System

__all__ = [
    "BORDER_BUDGET",
    "Look",
    "border_cells",
    "border_indices",
    "map_looks",
    "reexamine",
    "run_all",
    "run_look",
    "run_looks",
    "sweep_looks",
]

BORDER_BUDGET = 8000  # periods a border run's verdict may take, from the run's start


def _kind(r: RunRecord) -> str:
    first = next(iter(r.classification.values()), None)
    return r.status if first is None or r.status != "ok" else first.motion


def border_indices(runs: list[RunRecord]) -> list[int]:
    """Indices of a sweep's runs whose motion differs from the next or previous run's."""
    kinds = [_kind(r) for r in runs]
    out = set()
    for i in range(len(kinds) - 1):
        if kinds[i] != kinds[i + 1]:
            out.update((i, i + 1))
    return sorted(out)


def border_cells(kinds: np.ndarray) -> list[tuple[int, int]]:
    """Cells (i, j) of a grid of motion labels that differ from a 4-neighbour."""
    nx, ny = kinds.shape
    out = set()
    for i in range(nx):
        for j in range(ny):
            for a, b in ((i + 1, j), (i, j + 1)):
                if a < nx and b < ny and kinds[i, j] != kinds[a, b]:
                    out.update(((i, j), (a, b)))
    return sorted(out)


def needs_look(r: RunRecord) -> bool:
    """A border run is continued unless it failed or sits on a confirmed orbit."""
    return r.ok and r.verdict is not None and r.verdict.get("period") is None


def reexamine(
    system: System,
    r: RunRecord,
    *,
    tol: float,
    method: str = "dop853",
    rtol: float = 1e-8,
    atol: float = 1e-10,
    budget: int = BORDER_BUDGET,
) -> RunRecord:
    """``r`` continued from its end state with the long budget (see the module text);
    ``system`` is the model at ``r``'s values, ``tol`` the repeat tolerance relative to
    the Poincare cloud (``point.classification_tolerance``)."""
    if not needs_look(r) or r.x_final is None:
        return r
    _, points, x, before, tol = _start(system, r, tol)
    st = settle(
        system,
        points,
        x,
        0.0,  # the run ended on a whole number of forcing periods: the phase is 0
        periods_run=before,
        tol=tol,
        method=method,
        rtol=rtol,
        atol=atol,
        budget=max(budget, before),
        min_periods=budget,
    )
    return _finish(system, r, st, budget)


def _start(system: System, r: RunRecord, tol: float) -> tuple:
    """What :func:`settle` takes of a run: (system, Poincare points, end state, periods
    run, repeat tolerance scaled by the cloud)."""
    before = _before(r)
    points = r.tail.T
    cloud = max(float(np.ptp(points, axis=1).max()), 1.0) if points.size else 1.0
    return system, points, r.x_final, before, tol * cloud


def _finish(system: System, r: RunRecord, st, budget: int) -> RunRecord:
    """The run's record with the settled verdict (``reexamined`` says the periods before
    and the budget)."""
    v = st.verdict
    summary = v.summary() | {"reexamined": {"periods_before": _before(r), "budget": budget}}
    keep = r.tail.shape[0]
    lyap = st.lyapunov
    if lyap is not None:
        lyap = {"exponent": lyap["exponent"], "uncertainty": lyap["uncertainty"]}
    changes = dict(
        classification=per_coordinate(system, v),
        verdict=summary,
        lyapunov=lyap,
        poincare={s: st.points[k, -keep:].copy() for k, s in enumerate(system.states)},
        x_final=st.x_final.copy(),
    )
    if st.extremes is not None:
        lo, hi = st.extremes
        changes["extremes"] = {
            s: Extremes(float(hi[k]), float(lo[k])) for k, s in enumerate(system.states)
        }
    return replace(r, **changes)


def sweep_looks(
    system: System, parameter: str, runs: list[RunRecord], settings: dict
) -> list[tuple[int, Look]]:
    """The re-examinations a sweep needs: (index, :class:`Look`) for every border run
    that is not on a confirmed orbit (none when the sweep's ``budget`` setting is 0: no
    run may be continued).  ``system`` is the sweep's model at its base values."""
    from ..analysis.point import classification_tolerance
    from ..integrate import fastest_method

    if settings.get("budget", BUDGET) == 0:
        return []
    rtol = settings.get("rtol", 1e-8)
    method = settings.get("method") or fastest_method(rtol)
    options = {
        "tol": classification_tolerance(method, rtol),
        "method": method,
        "rtol": rtol,
        "atol": settings.get("atol", 1e-10),
        "budget": max(BORDER_BUDGET, settings.get("budget", BUDGET)),
    }
    out = []
    for i in border_indices(runs):
        if needs_look(runs[i]):
            at = system.with_values(**{parameter: runs[i].values[parameter]})
            out.append(
                (i, Look(str(at.module.__file__), tuple(map(float, at.p)), runs[i], options))
            )
    return out


@dataclass(frozen=True)
class Look:
    """One map run to re-examine, picklable for a worker: the model's file and parameter
    vector, the run, and the options of :func:`reexamine`."""

    source: str
    p: tuple
    record: RunRecord
    options: dict


def run_look(look: Look) -> RunRecord:
    system = System(load_generated(look.source), np.asarray(look.p, float), {})
    return reexamine(system, look.record, **look.options)


# Looks per task of :func:`run_all`: a fixed number (not a share per worker), so that the
# batches, and with them the lockstep groups whose steps the looks share, do not depend
# on how many workers run them.
LOOK_BATCH = 32


def run_looks(looks: list[Look]) -> list[RunRecord]:
    """Worker: :func:`run_look` of each look, their windows run together
    (``settle.settle_many``: the looks of one model, forcing frequency, options and
    budget in one lockstep batch per window, where one at a time each took its own steps);
    the records in the order of ``looks``."""
    out = [look.record for look in looks]
    groups: dict = {}
    for k, look in enumerate(looks):
        r = look.record
        if needs_look(r) and r.x_final is not None:
            budget = look.options.get("budget", BORDER_BUDGET)
            groups.setdefault((_options_key(look), budget, max(budget, _before(r))), []).append(k)
    for (_, budget, longest), ks in groups.items():
        o = looks[ks[0]].options
        systems = {
            k: System(load_generated(looks[k].source), np.asarray(looks[k].p, float), {})
            for k in ks
        }
        starts = [_start(systems[k], looks[k].record, looks[k].options["tol"]) for k in ks]
        done = settle_many(
            starts,
            method=o.get("method", "dop853"),
            rtol=o.get("rtol", 1e-8),
            atol=o.get("atol", 1e-10),
            budget=longest,
            min_periods=budget,
        )
        for k, st in zip(ks, done, strict=True):
            out[k] = _finish(systems[k], looks[k].record, st, budget)
    return out


def _before(r: RunRecord) -> int:
    """The periods a run went before its look."""
    return int(r.verdict.get("periods_run") or 0)


def _options_key(look: Look) -> tuple:
    """A look's options but its own tolerance (the tolerance is per run)."""
    return tuple(sorted((n, v) for n, v in look.options.items() if n != "tol"))


def _batch_key(look: Look):
    """What looks must share to run their windows in one batch, or None (a piecewise
    model's, whose runs take their own steps anyway)."""
    module = load_generated(look.source)
    contract = Contract.of(module)
    if contract.piecewise:
        return None
    omega = look.p[contract.parameters.index(contract.forcing_frequency)]
    return (look.source, omega, _options_key(look), _before(look.record))


def run_all(looks: list[Look], *, run=None, **options) -> list[RunRecord]:
    """Every look re-examined (:func:`run_looks`) in tasks of ``run``
    (``executor.map_tasks`` by default, or a result store's ``map``; ``options`` go to
    it): the looks whose windows can share a batch up to :data:`LOOK_BATCH` to a task,
    the others (a piecewise model's, a look alone at its frequency) one to a task; the
    records in the order of ``looks``."""
    if run is None:
        from ..executor import map_tasks as run
    # The looks settle_many can batch (one model, forcing frequency, options and start)
    # share a task, up to LOOK_BATCH; the rest, and a piecewise force law's (its runs take
    # their own steps in any batch: integrate.run), one to a task, spread over the workers
    groups: dict = {}
    for k, look in enumerate(looks):
        groups.setdefault(_batch_key(look), []).append(k)
    chunks: list[list[int]] = []
    for key, ks in groups.items():
        if key is None or len(ks) == 1:
            chunks += [[k] for k in ks]
        else:
            chunks += [ks[i : i + LOOK_BATCH] for i in range(0, len(ks), LOOK_BATCH)]
    chunks.sort()  # in the order of the looks, whatever the grouping
    parts = run(run_looks, [[looks[k] for k in ks] for ks in chunks], **options)
    out: list = [None] * len(looks)
    for ks, part in zip(chunks, parts, strict=True):
        for k, r in zip(ks, part, strict=True):
            out[k] = r
    return out


def map_looks(runs: dict, systems, shape, options: dict) -> list[tuple[tuple, int, Look]]:
    """The re-examinations a map needs: ``runs`` maps a cell (ix, iy) to its runs (the
    first is the forward start's), ``systems[ix][iy]`` is the cell's model; returns
    (cell, run index, :class:`Look`) for every run that needs a look at a border cell."""
    kinds = np.empty(shape, dtype=object)
    for (ix, iy), rs in runs.items():
        kinds[ix, iy] = _kind(rs[0])
    out = []
    for cell in border_cells(kinds):
        s = systems[cell[0]][cell[1]]
        for k, r in enumerate(runs[cell]):
            if needs_look(r):
                look = Look(str(s.module.__file__), tuple(map(float, s.p)), r, options)
                out.append((cell, k, look))
    return out
