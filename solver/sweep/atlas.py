"""Regime maps: where each kind of motion lives over two parameters, and which coexist.

For every point of an ``x`` by ``y`` grid, K initial states are integrated in the compiled
map engine (``integrate/native/maps.py``: lockstep groups, Poincare points, extremes at
every step, the exponent's variational system beside the state):

* ``forward``: the end state of the previous x value (same y), as a bifurcation diagram
  swept up in x; the first column starts from the loaded rest state;
* ``backward``: the same swept down in x;
* ``random-k`` (k = 3 .. K): a state drawn uniformly from ``box`` (per state, ``(lo, hi)``;
  default: coordinates from one half backlash beyond the lower contact edge to one beyond
  the upper, or within one unit of a planetary set's loaded equilibrium, velocities in
  [-1, 1]); each draw depends only on (seed, grid point, k).

Without a working C compiler the runs go through SciPy's integrators instead (the same
results to the tolerance, much slower: ``integrate/native/fallback.py``), after one warning
line; which one runs is decided once, here, not in every worker.

Each run is classified and the runs of a grid point grouped into attractors
(``attractors.py``).  Work goes in tasks -- the forward chain, the backward chain, and one
task per column of random starts -- run serially, on local processes or with dask
(``executor.py``); with ``store`` (a :class:`~.store.RunStore`, as for sweeps) every
finished column is written at once and a rerun resumes where the last one stopped.
"""

from __future__ import annotations

import hashlib
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .._json import dumps
from ..analysis.record import RunRecord
from ..analysis.settle import BUDGET
from ..contract import Contract, load_generated
from ..executor import map_tasks
from ..integrate.native.engine import batch_shared
from ..integrate.run import Batch, decide_backend, integrate
from ..integrate.simulate import default_initial_state
from ..integrate.spec import RunSpec
from ..system import System
from .attractors import group_runs, outcome
from .borders import BORDER_BUDGET, map_looks, run_all
from .maps_result import Cell, RegimeMap
from .progress import Progress
from .store import RunStore

__all__ = ["default_box", "regime_map"]


def default_box(system: System) -> dict[str, tuple[float, float]]:
    """Where random initial states are drawn: see the module text.  A model that states
    its loaded equilibrium and has no mesh coordinates (a planetary set's body
    coordinates) draws each coordinate within one unit of it instead."""
    c = system.contract
    box = {s: (-1.0, 1.0) for s in c.states}
    static = getattr(system.module, "static_state", None)
    at = static(system.p) if static is not None and not c.contact else None
    for coord in c.coordinates:
        if at is not None:
            mid = float(at[c.index(coord)])
            box[coord] = (mid - 1.0, mid + 1.0)
            continue
        lower, upper = c.contact.get(coord, (-1.0, 1.0))
        box[coord] = (lower - 1.0, upper + 1.0)
    return box


def _random_state(seed: int, ix: int, iy: int, k: int, box, states) -> np.ndarray:
    rng = np.random.default_rng([seed, ix, iy, k])
    return np.array([rng.uniform(*box[s]) for s in states])


@dataclass(frozen=True)
class _Column:
    """The runs of one start kind at one x value: per y, the model file, p and x0, and
    the runs' keys in the store (``key`` to ``key + len(files) - 1``)."""

    ix: int
    kind: str  # "forward", "backward" or "random"
    files: tuple[str, ...]
    P: tuple  # ny * m parameter vectors (models may differ along an open-value axis)
    X0: np.ndarray | None  # (ny * m, n); None: chained (previous column's end states)
    starts: tuple[str, ...]
    values: tuple[dict, ...]  # each run's grid point: {x name: value, y name: value}
    key: int


def _run_column(col: _Column, X0: np.ndarray, opts: dict) -> list[RunRecord]:
    """Integrate one column (grouped by model file and forcing frequency) and classify."""
    out: list[RunRecord | None] = [None] * len(col.files)
    modules = {f: load_generated(f) for f in set(col.files)}
    by_model: dict = {}
    contracts = {f: Contract.of(m) for f, m in modules.items()}
    for i, f in enumerate(col.files):
        c = contracts[f]
        w = col.P[i][c.parameters.index(c.forcing_frequency)]
        by_model.setdefault((f, float(w)), []).append(i)
    for (f, _), idx in by_model.items():
        module = modules[f]
        batch = Batch.of(module, np.array([col.P[i] for i in idx]))
        res = integrate(batch, X0[idx], opts["spec"], backend=opts["backends"][f])
        for r, i in enumerate(idx):
            system = System(module, col.P[i], {}, contracts[f])
            out[i] = outcome(
                system,
                col.starts[i],
                res.status[r],
                res.x[r],
                res.xmin[r],
                res.xmax[r],
                None if res.exponent is None else res.exponent[r],
                tol=opts["tol"],
                rtol=opts["rtol"],
                engine=f"{res.label} (map)",
                atol=opts["atol"],
                values=col.values[i],
                x0=X0[i],
                t_end=opts["spec"].t0 + (opts["transient"] + opts["periods"]) * system.period,
                method=opts["method"],
                budget=opts["budget"],
            )
    return out  # type: ignore[return-value]


@dataclass(frozen=True, eq=False)
class _Task:
    """One worker's share of a map: a chain of columns (each from the previous one's end
    states; ``first_x0`` the first column's starts) or one column of independent starts;
    the runs the store already holds of them (``stored``, by key) and the store to add
    to."""

    columns: tuple[_Column, ...]
    first_x0: np.ndarray | None
    opts: dict
    store: RunStore | None
    stored: dict


def _task(task: _Task) -> list[tuple[str, int, list[RunRecord]]]:
    """One task: a chain of columns (each from the previous one's end states) or one
    column of independent starts.  Finished columns go to the store at once; columns
    the store holds (``stored``, by key) are not run again."""
    columns, first_x0, opts, store, stored = (
        task.columns,
        task.first_x0,
        task.opts,
        task.store,
        task.stored,
    )
    done = []
    x0 = first_x0
    for col in columns:
        keys = range(col.key, col.key + len(col.files))
        runs = [stored[k] for k in keys] if all(k in stored for k in keys) else None
        if runs is None:
            start = col.X0 if col.X0 is not None else x0
            runs = _run_column(col, start, opts)
            if store is not None:
                store.append(dict(zip(keys, runs, strict=True)))
        done.append((col.kind, col.ix, runs))
        # the next column of a chain starts where this one ended (or, after a failure,
        # from the column's own start)
        ends = [r.x_final if r.status == "ok" else None for r in runs]
        start = col.X0 if col.X0 is not None else x0
        x0 = np.array([e if e is not None else start[k] for k, e in enumerate(ends)])
    return done


def regime_map(
    system: System,
    x: tuple[str, np.ndarray],
    y: tuple[str, np.ndarray],
    *,
    initial_states: int = 4,
    seed: int = 0,
    box: dict | None = None,
    transient: int = 300,
    periods: int = 100,
    lyapunov_periods: int = 200,
    method: str = "dop853",
    rtol: float = 1e-8,
    atol: float = 1e-10,
    executor: str = "processes",
    workers: int | None = None,
    scheduler: str | None = None,
    store: str | Path | None = None,
    progress: bool = False,
    resolve=None,
    budget: int = BUDGET,
) -> RegimeMap:
    """Map the attractors of ``system`` over ``x = (name, values)`` by ``y``.

    ``resolve(values) -> System`` builds the system of one grid point from its two named
    values (default ``system.with_values``; the application layer passes one that
    re-derives the model for values that need it).  See the module text for the initial
    states and the store.
    """
    from ..analysis.point import classification_tolerance

    started = time.perf_counter()
    (xn, xv), (yn, yv) = x, y
    xv, yv = np.asarray(xv, float), np.asarray(yv, float)
    if xn == yn:
        raise ValueError(f"the two axes must be different parameters, both are '{xn}'")
    if initial_states < 1:
        raise ValueError(f"initial_states must be >= 1, got {initial_states}")
    # the run's options, checked once here (before any work), for every task
    spec = RunSpec(
        method=method,
        rtol=rtol,
        atol=atol,
        transient=transient,
        periods=periods,
        collect=("samples", "extremes", "exponent")[: 3 if lyapunov_periods else 2],
        lyapunov_periods=lyapunov_periods,
        seed=seed,
        valid_range="stop",
    )
    resolve = resolve or (lambda values: system.with_values(**values))
    grid = [[resolve({xn: float(a), yn: float(b)}) for b in yv] for a in xv]
    states = system.states
    box = {**default_box(system), **(box or {})}
    unknown = sorted(set(box) - set(states))
    if unknown:
        raise ValueError(f"box: {', '.join(unknown)} not a state; states: {', '.join(states)}")
    n_random = max(initial_states - 2, 0)
    opts = dict(
        method=method,
        rtol=rtol,
        atol=atol,
        transient=transient,
        periods=periods,
        lyapunov_periods=lyapunov_periods,
        seed=seed,
        tol=classification_tolerance(method, rtol),
        budget=budget,
    )
    hashes = sorted({g.model_hash for col in grid for g in col})
    nx, ny = len(xv), len(yv)
    first_key = {"forward": 0, "backward": nx * ny, "random": 2 * nx * ny}

    def column(ix: int, kind: str) -> _Column:
        cells = grid[ix]
        if kind == "random":
            starts = [f"random-{k + 3}" for _ in cells for k in range(n_random)]
            files = [g.module.__file__ for g in cells for _ in range(n_random)]
            P = tuple(g.p for g in cells for _ in range(n_random))
            X0 = np.array(
                [
                    _random_state(seed, ix, iy, k + 3, box, states)
                    for iy in range(len(cells))
                    for k in range(n_random)
                ]
            )
            named = tuple({xn: float(xv[ix]), yn: float(b)} for b in yv for _ in range(n_random))
            key = first_key[kind] + ix * ny * n_random
            return _Column(ix, kind, tuple(files), P, X0, tuple(starts), named, key)
        files = tuple(g.module.__file__ for g in cells)
        named = tuple({xn: float(xv[ix]), yn: float(b)} for b in yv)
        P = tuple(g.p for g in cells)
        return _Column(ix, kind, files, P, None, (kind,) * ny, named, first_key[kind] + ix * ny)

    # the compiled library of every model, built once here (or the fallback, warned once)
    # (checked with the library of the model's rows of its first column: a column's
    # rows share every parameter but the y axis's, and so do every column's)
    models = {g.module.__file__: g.module for col in grid for g in col}
    rows = {}
    for col in grid:
        for g in col:
            rows.setdefault(g.module.__file__, {}).setdefault(id(col), []).append(g.p)
    backends = {
        f: decide_backend(
            m, spec, shared=batch_shared(m, np.array(next(iter(rows[f].values()))), spec)
        )
        for f, m in models.items()
    }
    where = {"native": "compiled", "numpy": "NumPy fallback"}
    engine = ", ".join(sorted({f"{where[b]} {method.upper()}" for b in backends.values()}))
    run_opts = {**opts, "spec": spec, "backends": backends}
    chains = {"forward": range(nx), "backward": range(nx - 1, -1, -1)}
    planned = [
        ([column(ix, kind) for ix in chains[kind]], grid[chains[kind][0]])
        for kind in list(chains)[: min(initial_states, 2)]
    ]
    planned += [([column(ix, "random")], None) for ix in range(nx) if n_random]
    opened = None
    if store is not None:
        opened = RunStore.open(
            Path(store),
            kind="map",
            model_hash=hashes,
            values={xn: xv.tolist(), yn: yv.tolist()},
            model=system.name,
            base_values={k: float(v) for k, v in system.values.items()},
            settings={**opts, "initial_states": initial_states, "box": box},
        )
    try:
        stored = {} if opened is None else opened.read()
        tasks = []
        for columns, cells in planned:
            first = None if cells is None else np.array([default_initial_state(g) for g in cells])
            keys = {k for col in columns for k in range(col.key, col.key + len(col.files))}
            held = {k: r for k, r in stored.items() if k in keys}
            tasks.append(_Task(tuple(columns), first, run_opts, opened, held))
        bar = Progress(len(tasks), "map", enabled=progress)
        results = map_tasks(
            _task,
            tasks,
            executor=executor,
            workers=workers,
            scheduler=scheduler,
            on_result=lambda _r: bar.step(),
        )
    finally:
        if opened is not None:
            opened.close()
    runs: dict[tuple[int, int], list[RunRecord]] = {}
    order = {"forward": 0, "backward": 1, "random": 2}
    for part in results:
        for kind, ix, column_runs in sorted(part, key=lambda p: order[p[0]]):
            per = 1 if kind != "random" else n_random
            for k, r in enumerate(column_runs):
                runs.setdefault((ix, k // per), []).append(r)
    runs = {cell: _ordered(rs) for cell, rs in runs.items()}
    looks = map_looks(runs, grid, (nx, ny), _look_options(opts)) if opts["budget"] else []
    if looks:
        looked = run_all([lk for _, _, lk in looks], executor=executor, workers=workers)
        for (cell, k, _), r in zip(looks, looked, strict=True):
            runs[cell][k] = r
    cells = tuple(
        tuple(
            Cell(float(a), float(b), tuple(group_runs(runs[(ix, iy)]))) for iy, b in enumerate(yv)
        )
        for ix, a in enumerate(xv)
    )
    return RegimeMap(
        model=system.name,
        model_hashes=tuple(hashes),
        x=xn,
        x_values=xv,
        y=yn,
        y_values=yv,
        states=tuple(states),
        coordinates=tuple(system.coordinates),
        values={k: float(v) for k, v in system.values.items()},
        settings={**opts, "initial_states": initial_states, "box": box, "engine": engine},
        cells=cells,
        wall_time=time.perf_counter() - started,
        digest=hashlib.sha256(dumps([hashes, xv.tolist(), yv.tolist()]).encode()).hexdigest(),
        resumed=len(stored),
    )


def _look_options(opts: dict) -> dict:
    """What a border run's re-examination needs of the map's options."""
    keys = ("tol", "method", "rtol", "atol")
    budget = max(BORDER_BUDGET, opts["budget"])
    return {k: opts[k] for k in keys} | {"budget": budget}


def _ordered(runs: list[RunRecord]) -> list[RunRecord]:
    rank = {"forward": 0, "backward": 1}
    return sorted(runs, key=lambda r: (rank.get(r.start, 2), r.start))
