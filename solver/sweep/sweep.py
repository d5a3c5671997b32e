"""Parameter sweeps: bifurcation diagrams over one named parameter.

A sweep runs :func:`~gearsym.solver.analysis.point.analyse_point` over the values of one
named parameter (a scene parameter such as ``lambda`` or ``f1``, or a model parameter).
With continuation each point starts from the previous point's final state, forward or
backward, so that coexisting attractors show up as hysteresis; without it every point
starts from the same state and points are independent, so they run in parallel.

Work goes out as chains (``chains.py``: a continuation chain, one independent point, or
with a compiled method a chunk of independent points integrated together in the lockstep
engine) through the one executor (``executor.py``); workers rebuild the system from the
generated module's name, so nothing unpicklable crosses processes, and each point comes
back as a :class:`~..analysis.record.RunRecord`, already written to the store.
"""

from __future__ import annotations

import json
from collections.abc import Sequence
from dataclasses import dataclass, field, replace
from functools import partial
from pathlib import Path

import numpy as np

from .._json import dumps
from ..analysis.record import RunRecord
from ..executor import EXECUTORS, map_tasks
from ..system import System
from .borders import run_all, sweep_looks
from .chains import Chain, ChainDone, checked_values, module_ref, plan, run_chain
from .progress import Progress
from .result import SweepResult
from .store import RunStore, SweepStoreError

__all__ = [
    "Progress",
    "SweepJob",
    "SweepResult",
    "SweepStoreError",
    "module_ref",
    "sweep",
    "sweep_many",
]


def _execute(
    chains: list[Chain],
    executor: str,
    workers: int | None,
    progress: Progress | None,
    scheduler: str | None = None,
) -> list[ChainDone]:
    if executor not in EXECUTORS:
        raise ValueError(f"unknown executor '{executor}'; executors: {', '.join(EXECUTORS)}")

    def tick(point):
        if progress:
            progress.step(f"{chains[0].parameter}={point.value:.4g}")

    if not chains:  # everything was in the store
        return []
    if executor == "serial" or (executor == "processes" and len(chains) <= 1):
        # In this process: progress point by point, also inside a chain.
        return map_tasks(partial(run_chain, on_point=tick), chains)

    def ticks(done: ChainDone):
        for point in done.points:
            tick(point)

    _decide_native(chains, executor, workers)

    return map_tasks(
        run_chain, chains, executor=executor, workers=workers, scheduler=scheduler, on_result=ticks
    )


def _decide_native(chains: list[Chain], executor: str, workers: int | None) -> None:
    """Build the compiled libraries of every model the chains run before the workers
    start (they find them cached; the workers build them side by side), and say here,
    once per reason, when one cannot be built: workers ignore that warning."""
    from ..integrate.methods import get_method
    from ..integrate.native.build import prebuild, single_point
    from ..integrate.native.maps import map_backend
    from ..integrate.simulate import fastest_method

    seen = {}
    for chain in chains:
        settings = chain.settings
        method = settings.get("method") or fastest_method(settings.get("rtol", 1e-8))
        tangent = bool(settings.get("lyapunov_periods", 0))
        if get_method(method).family != "native" or (chain.module, tangent) in seen:
            continue
        seen[(chain.module, tangent)] = System.load(chain.module, **chain.base_values).module
    # the libraries of the chains' one-point runs (the check below is made on them)
    prebuild(
        [
            (module.__file__, v, single_point(module))
            for (_, tangent), module in seen.items()
            for v in (False, True)[: 1 + tangent]
        ],
        executor=executor,
        workers=workers,
    )
    for (_, tangent), module in seen.items():
        if map_backend(module, lyapunov=False) == "native" and tangent:
            map_backend(module, lyapunov=True)


def _result(system, parameter, values, direction, settings, points) -> SweepResult:
    return SweepResult(
        model=system.name,
        model_hash=system.model_hash,
        parameter=parameter,
        values=np.asarray(values, dtype=float),
        direction=direction,
        base_values={k: float(v) for k, v in system.values.items()},
        settings=dict(settings),
        points=points,
        scales=system.scales(),
    )


def sweep(
    system: System,
    parameter: str,
    values: Sequence[float],
    *,
    continuation: bool = True,
    backward: bool = False,
    x0=None,
    executor: str = "serial",
    workers: int | None = None,
    progress: Progress | None = None,
    store: Path | None = None,
    scheduler: str | None = None,
    **settings,
) -> SweepResult:
    """Sweep ``parameter`` over ``values`` (see module docstring); ``settings`` go to
    :func:`analyse_point` (method, rtol, transient, periods, ...).

    A point whose integration fails is tried once more, then recorded as ``failed`` with
    its error.  With ``store`` (a folder) every finished point is written there at once;
    running the same sweep into the same folder again resumes where it stopped, and a
    folder written by another model version or another sweep is refused.
    """
    values = checked_values(system, parameter, values, x0)  # before any folder is created
    run = _Planned.of(system, parameter, values, continuation, backward, x0, settings, store)
    try:
        if progress is not None:
            for _ in run.done:
                progress.step("(stored)")
        ran = _execute(run.chains, executor, workers, progress, scheduler)
        points, stored = run.ordered(ran)
        looked = _looked([run], [points], executor, workers, scheduler)[0]
        return run.result(points, stored, looked)
    finally:
        run.close()


def _looked(runs: list, points: list[list], executor, workers, scheduler) -> list[list]:
    """Each sweep's runs with its border runs re-examined (``borders``), all sweeps' in
    one batch of the executor (one at a time in this process, the long re-examinations of
    a chaotic region left the workers idle)."""
    looks, where = [], []
    for k, (run, pts) in enumerate(zip(runs, points, strict=True)):
        for i, look in sweep_looks(run.system, run.parameter, pts, run.settings):
            looks.append(look)
            where.append((k, i))
    out = [list(pts) for pts in points]
    if not looks:
        return out
    done = run_all(looks, executor=executor, workers=workers, scheduler=scheduler)
    for (k, i), r in zip(where, done, strict=True):
        out[k][i] = r
    return out


def _direction(continuation: bool, backward: bool) -> str:
    return ("backward" if backward else "forward") if continuation else "independent"


@dataclass
class _Planned:
    """One sweep planned: its chains, the points its store already holds (``done``, with
    their stored JSON ``texts``), and how to assemble the result from what the chains ran.
    :func:`sweep` and :func:`sweep_many` share it, so both resume from a store."""

    system: System
    parameter: str
    values: np.ndarray
    continuation: bool
    backward: bool
    settings: dict
    x0: list | None
    store: RunStore | None
    chains: list
    done: dict
    texts: dict

    @classmethod
    def of(cls, system, parameter, values, continuation, backward, x0, settings, store) -> _Planned:
        x0_list = None if x0 is None else [float(v) for v in x0]
        done: dict[int, RunRecord] = {}
        texts: dict[int, str] = {}
        opened = None
        if store is not None:
            opened = RunStore.open(
                Path(store),
                kind="sweep",
                model_hash=system.model_hash,
                values={parameter: [float(v) for v in values]},
                model=system.name,
                direction=_direction(continuation, backward),
                base_values={k: float(v) for k, v in system.values.items()},
                settings=json.loads(dumps(settings)),
                x0=x0_list,
            )
            done = opened.read(_in_order(parameter, values, backward), texts)
        try:
            chains = plan(
                system,
                parameter,
                values,
                continuation=continuation,
                backward=backward,
                x0=x0,
                settings=settings,
                done=done,
                store=opened,
            )
        except BaseException:
            if opened is not None:
                opened.close()
            raise
        values = np.asarray(values, dtype=float)
        return cls(
            system,
            parameter,
            values,
            continuation,
            backward,
            dict(settings),
            x0_list,
            opened,
            chains,
            done,
            texts,
        )

    def ordered(self, ran: list[ChainDone]) -> tuple[list, list]:
        """The sweep's runs in its order, and their stored texts (None: not stored)."""
        found, texts = dict(self.done), dict(self.texts)
        for chain, done in zip(self.chains, ran, strict=True):
            found.update(zip(chain.indices, done.points, strict=True))
            texts.update(zip(chain.indices, done.texts, strict=True))
        order = range(self.values.size)
        order = order[::-1] if self.backward else order
        return [found[i] for i in order], [texts.get(i) for i in order]

    def result(self, points: list, stored: list, looked: list) -> SweepResult:
        """The sweep's result from its runs in order (``ordered``) and the same runs with
        its border runs re-examined (``looked``)."""
        if any(a is not b for a, b in zip(looked, points, strict=True)):
            points, stored = looked, [None]  # re-examined points: their stored text is old
        settings = dict(self.settings, x0=self.x0)
        direction = _direction(self.continuation, self.backward)
        result = _result(self.system, self.parameter, self.values, direction, settings, points)
        result = replace(result, resumed=len(self.done))
        if self.store is None or None in stored:
            return result
        return replace(result, texts=stored)

    def close(self) -> None:
        if self.store is not None:
            self.store.close()  # the lock, for the next writer


def _in_order(parameter: str, values, backward: bool):
    """The store's check of a sweep's run: its key is its place in the sweep's order,
    and its value the one there."""
    values = [float(v) for v in values]
    order = values[::-1] if backward else values

    def check(key: int, record: RunRecord) -> None:
        if not 0 <= key < len(order) or record.values != {parameter: order[key]}:
            raise ValueError("another value")

    return check


@dataclass(frozen=True)
class SweepJob:
    """One continuation sweep of :func:`sweep_many`: ``settings`` go to analyse_point."""

    system: System
    parameter: str
    values: Sequence[float]
    backward: bool = False
    x0: Sequence[float] | None = None
    settings: dict = field(default_factory=dict)
    store: str | Path | None = None  # a folder: finished points kept there, resumed from


def sweep_many(
    jobs: list[SweepJob],
    *,
    executor: str = "processes",
    workers: int | None = None,
    progress: Progress | None = None,
    scheduler: str | None = None,
) -> list[SweepResult]:
    """Several continuation sweeps run side by side, one chain per worker process; a job
    with a ``store`` keeps its finished points there and resumes from them."""
    runs = []
    try:
        for job in jobs:
            runs.append(
                _Planned.of(
                    job.system,
                    job.parameter,
                    job.values,
                    True,
                    job.backward,
                    job.x0,
                    dict(job.settings),
                    job.store,
                )
            )
        pending = [(k, c) for k, run in enumerate(runs) for c in run.chains]
        if progress is not None:
            for run in runs:
                for _ in run.done:
                    progress.step("(stored)")
        ran = _execute([c for _, c in pending], executor, workers, progress, scheduler)
        by_run: dict[int, list[ChainDone]] = {k: [] for k in range(len(runs))}
        for (k, _), done in zip(pending, ran, strict=True):
            by_run[k].append(done)
        ordered = [run.ordered(by_run[k]) for k, run in enumerate(runs)]
        looked = _looked(runs, [p for p, _ in ordered], executor, workers, scheduler)
        return [run.result(p, s, lk) for run, (p, s), lk in zip(runs, ordered, looked, strict=True)]
    finally:
        for run in runs:
            run.close()
