"""Regime maps: where each kind of motion lives over two parameters, and which coexist.

For every point of an ``x`` by ``y`` grid, K initial states are integrated in the compiled
map engine (``integrate/native/maps.py``: lockstep groups, Poincare points, extremes at
every step, the exponent's variational system beside the state):

* ``forward``: the end state of the previous x value (same y), as a bifurcation diagram
  swept up in x; the first column starts from the loaded rest state;
* ``backward``: the same swept down in x;
* ``random-k`` (k = 3 .. K): a state drawn uniformly from ``box`` (per state, ``(lo, hi)``;
  default: coordinates from one half backlash beyond the lower contact edge to one beyond
  the upper, velocities in [-1, 1]); each draw depends only on (seed, grid point, k).

Without a working C compiler the runs go through SciPy's integrators instead (the same
results to the tolerance, much slower: ``integrate/native/fallback.py``), after one warning
line; which one runs is decided once, here, not in every worker.

Each run is classified and the runs of a grid point grouped into attractors
(``attractors.py``).  Work goes in tasks -- the forward chain, the backward chain, and one
task per column of random starts -- run serially, on local processes or with dask
(``executor.py``); with ``store`` every finished column is written at once and a rerun
resumes where the last one stopped.
"""

from __future__ import annotations

import hashlib
import json
import os
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .._json import dumps
from ..contract import load_generated
from ..integrate.native.maps import map_backend, run_map
from ..integrate.simulate import default_initial_state
from ..system import System
from .attractors import RunOutcome, group_runs, outcome
from .executor import map_tasks
from .maps_result import Cell, RegimeMap, outcome_from_dict, outcome_to_dict
from .progress import Progress
from .store import SweepStoreError, lock_store

__all__ = ["default_box", "regime_map"]


def default_box(system: System) -> dict[str, tuple[float, float]]:
    """Where random initial states are drawn: see the module text."""
    c = system.contract
    box = {s: (-1.0, 1.0) for s in c.states}
    for coord in c.coordinates:
        lower, upper = c.contact.get(coord, (-1.0, 1.0))
        box[coord] = (lower - 1.0, upper + 1.0)
    return box


def _random_state(seed: int, ix: int, iy: int, k: int, box, states) -> np.ndarray:
    rng = np.random.default_rng([seed, ix, iy, k])
    return np.array([rng.uniform(*box[s]) for s in states])


@dataclass(frozen=True)
class _Column:
    """The runs of one start kind at one x value: per y, the model file, p and x0."""

    ix: int
    kind: str  # "forward", "backward" or "random"
    files: tuple[str, ...]
    P: tuple  # ny * m parameter vectors (models may differ along an open-value axis)
    X0: np.ndarray | None  # (ny * m, n); None: chained (previous column's end states)
    starts: tuple[str, ...]


def _run_column(col: _Column, X0: np.ndarray, opts: dict) -> list[RunOutcome]:
    """Integrate one column (grouped by model file and forcing frequency) and classify."""
    out: list[RunOutcome | None] = [None] * len(col.files)
    modules = {f: load_generated(f) for f in set(col.files)}
    by_model: dict = {}
    for i, f in enumerate(col.files):
        c = modules[f].CONTRACT
        w = col.P[i][list(c["parameters"]).index(c["forcing_frequency"])]
        by_model.setdefault((f, float(w)), []).append(i)
    run_opts = {k: opts[k] for k in ("method", "rtol", "atol", "transient", "periods")}
    for (f, _), idx in by_model.items():
        module = modules[f]
        res = run_map(
            module,
            np.array([col.P[i] for i in idx]),
            X0[idx],
            lyapunov_periods=opts["lyapunov_periods"],
            seed=opts["seed"],
            backend=opts["backends"][f],
            **run_opts,
        )
        base = System(module, col.P[idx[0]])
        for r, i in enumerate(idx):
            system = System(module, col.P[i], {}, base.contract)
            out[i] = outcome(
                system,
                col.starts[i],
                res.status[r],
                res.poincare[r],
                res.xmin[r],
                res.xmax[r],
                None if res.lyapunov is None else res.lyapunov[r],
                tol=opts["tol"],
                rtol=opts["rtol"],
                engine=f"{'compiled' if res.backend == 'native' else 'SciPy'} "
                f"{run_opts['method'].upper()} (map)",
                atol=opts["atol"],
            )
    return out  # type: ignore[return-value]


def _column_file(store: Path, kind: str, ix: int) -> Path:
    return store / "columns" / f"{kind}-{ix:04d}.json"


def _save_column(store: Path | None, col: _Column, runs: list[RunOutcome]) -> None:
    if store is None:
        return
    path = _column_file(store, col.kind, col.ix)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    tmp.write_text(dumps([outcome_to_dict(r) for r in runs]), encoding="utf-8")
    os.replace(tmp, path)


def _load_column(store: Path | None, kind: str, ix: int) -> list[RunOutcome] | None:
    if store is None:
        return None
    path = _column_file(store, kind, ix)
    try:
        return [outcome_from_dict(d) for d in json.loads(path.read_text(encoding="utf-8"))]
    except (OSError, ValueError, KeyError, TypeError):
        return None


def _task(task) -> list[tuple[str, int, list[RunOutcome]]]:
    """One task: a chain of columns (each from the previous one's end states) or one
    column of independent starts.  Finished columns go to the store at once."""
    columns, first_x0, opts, store = task
    done = []
    x0 = first_x0
    for col in columns:
        runs = _load_column(store, col.kind, col.ix)
        if runs is None:
            start = col.X0 if col.X0 is not None else x0
            runs = _run_column(col, start, opts)
            _save_column(store, col, runs)
        done.append((col.kind, col.ix, runs))
        # the next column of a chain starts where this one ended (or, after a failure,
        # from the column's own start)
        ends = [r.tail[-1] if r.status == "ok" else None for r in runs]
        start = col.X0 if col.X0 is not None else x0
        x0 = np.array([e if e is not None else start[k] for k, e in enumerate(ends)])
    return done


def _check_store(store: Path, manifest: dict) -> None:
    store.mkdir(parents=True, exist_ok=True)
    lock_store(store)  # one writer at a time, as for sweeps
    path = store / "manifest.json"
    if path.exists():
        old = json.loads(path.read_text(encoding="utf-8"))
        differs = [k for k in manifest if old.get(k) != json.loads(dumps(manifest[k]))]
        if differs:
            raise SweepStoreError(
                f"{store} holds another map ({', '.join(differs)} differ); choose another "
                "output folder or delete it"
            )
        return
    tmp = store / ".manifest.json.tmp"
    tmp.write_text(dumps(manifest, indent=1), encoding="utf-8")
    os.replace(tmp, path)


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
    if not 0 <= lyapunov_periods <= transient + periods:
        raise ValueError(
            f"lyapunov_periods must be in [0, transient + periods = {transient + periods}]"
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
    )
    root = None if store is None else Path(store)
    hashes = sorted({g.model_hash for col in grid for g in col})
    if root is not None:
        _check_store(
            root,
            {
                "kind": "regime map",
                "model_hashes": hashes,
                "x": {xn: xv.tolist()},
                "y": {yn: yv.tolist()},
                "values": {k: float(v) for k, v in system.values.items()},
                "settings": {**opts, "initial_states": initial_states, "box": box},
            },
        )

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
            return _Column(ix, kind, tuple(files), P, X0, tuple(starts))
        files = tuple(g.module.__file__ for g in cells)
        return _Column(ix, kind, files, tuple(g.p for g in cells), None, (kind,) * len(cells))

    # the compiled library of every model, built once here (or the fallback, warned once)
    tangent = lyapunov_periods > 0
    models = {g.module.__file__: g.module for col in grid for g in col}
    run_opts = {**opts, "backends": {f: map_backend(m, tangent) for f, m in models.items()}}
    tasks = []
    chains = {"forward": range(len(xv)), "backward": range(len(xv) - 1, -1, -1)}
    for kind in list(chains)[: min(initial_states, 2)]:
        order = list(chains[kind])
        first = np.array([default_initial_state(g) for g in grid[order[0]]])
        tasks.append(([column(ix, kind) for ix in order], first, run_opts, root))
    if n_random:
        tasks += [([column(ix, "random")], None, run_opts, root) for ix in range(len(xv))]
    bar = Progress(len(tasks), "map", enabled=progress)
    results = map_tasks(
        _task,
        tasks,
        executor=executor,
        workers=workers,
        scheduler=scheduler,
        on_result=lambda _r: bar.step(),
    )
    runs: dict[tuple[int, int], list[RunOutcome]] = {}
    order = {"forward": 0, "backward": 1, "random": 2}
    for part in results:
        for kind, ix, column_runs in sorted(part, key=lambda p: order[p[0]]):
            per = 1 if kind != "random" else n_random
            for k, r in enumerate(column_runs):
                runs.setdefault((ix, k // per), []).append(r)
    cells = tuple(
        tuple(
            Cell(float(a), float(b), tuple(group_runs(_ordered(runs[(ix, iy)]))))
            for iy, b in enumerate(yv)
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
        settings={**opts, "initial_states": initial_states, "box": box},
        cells=cells,
        wall_time=time.perf_counter() - started,
        digest=hashlib.sha256(dumps([hashes, xv.tolist(), yv.tolist()]).encode()).hexdigest(),
    )


def _ordered(runs: list[RunOutcome]) -> list[RunOutcome]:
    rank = {"forward": 0, "backward": 1}
    return sorted(runs, key=lambda r: (rank.get(r.start, 2), r.start))
