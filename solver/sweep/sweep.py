"""Parameter sweeps: bifurcation diagrams over one named parameter.

A sweep runs :func:`~gearsym.solver.analysis.point.analyse_point` over the values of one
named parameter (a scene parameter such as ``lambda`` or ``f1``, or a model parameter).
With continuation each point starts from the previous point's final state, forward or
backward, so that coexisting attractors show up as hysteresis; without it every point
starts from the same state and points are independent, so they run in parallel.

Work goes out as chains (a continuation chain, or one independent point) through the one
executor (``executor.py``); workers rebuild the system from the generated module's name,
so nothing unpicklable crosses processes, and each point comes back as a
:class:`~.points.SweepPoint`.
"""

from __future__ import annotations

import json
from collections.abc import Sequence
from dataclasses import dataclass, field
from functools import partial
from pathlib import Path

import numpy as np

from .._json import dumps
from ..analysis.point import analyse_point
from ..integrate import SimulationError
from ..system import System
from .executor import EXECUTORS, map_tasks
from .points import SweepPoint
from .progress import Progress
from .store import STORE_FORMAT, SweepStoreError, open_store, store_point

__all__ = ["Progress", "SweepJob", "SweepResult", "SweepStoreError", "sweep", "sweep_many"]


@dataclass(frozen=True)
class SweepResult:
    """Per-point summaries of a sweep (in the order of ``values``)."""

    model: str
    model_hash: str
    parameter: str
    values: np.ndarray
    direction: str  # "forward", "backward" or "independent"
    base_values: dict
    settings: dict
    points: list = field(default_factory=list)  # SweepPoint, in the order of values
    scales: dict = field(default_factory=dict)  # omega_n and half backlash: back to SI

    def poincare(self, state: str) -> list[np.ndarray]:
        return [np.asarray(p.poincare[state]) for p in self.points]

    def motion(self, coordinate: str) -> list[str]:
        return [p.motion(coordinate) for p in self.points]

    def maxima(self, state: str) -> np.ndarray:
        """Max of ``state`` at every point (NaN where a point failed)."""
        return np.array([p.max(state) for p in self.points])

    def minima(self, state: str) -> np.ndarray:
        """Min of ``state`` at every point (NaN where a point failed)."""
        return np.array([p.min(state) for p in self.points])

    def to_dict(self) -> dict:
        return {
            "model": self.model,
            "model_hash": self.model_hash,
            "parameter": self.parameter,
            "values": self.values.tolist(),
            "direction": self.direction,
            "base_values": self.base_values,
            "settings": self.settings,
            "scales": self.scales,
            "points": [p.to_dict() for p in self.points],
        }

    def to_table(self) -> tuple[list, list]:
        """One row per point: the value, status, motion of each coordinate, max and min of
        each state, and the largest Lyapunov exponent."""
        if not self.points:
            return [self.parameter, "status"], []
        coords = list(self.points[0].classification)
        states = list(self.points[0].extremes)
        columns = [
            self.parameter,
            "status",
            *(f"motion_{c}" for c in coords),
            *(f"{k}_{s}" for s in states for k in ("max", "min")),
            "lyapunov",
        ]
        rows = [
            [
                p.value,
                p.status,
                *(p.motion(c) for c in coords),
                *(f(s) for s in states for f in (p.max, p.min)),
                p.lyapunov_exponent,
            ]
            for p in self.points
        ]
        return columns, rows

    def save(self, path: Path) -> Path:
        """Write the sweep (parameter values, scales and model hash included): ``.json``,
        ``.csv`` or ``.mat`` (see ``solver/export.py``)."""
        from ..export import save

        return save(self, path)

    @classmethod
    def load(cls, path: Path) -> SweepResult:
        d = json.loads(Path(path).read_text(encoding="utf-8"))
        return cls(
            d["model"],
            d["model_hash"],
            d["parameter"],
            np.asarray(d["values"]),
            d["direction"],
            d["base_values"],
            d["settings"],
            [SweepPoint.from_dict(p) for p in d["points"]],
            d.get("scales", {}),
        )


def _checked(system: System, parameter: str, values) -> np.ndarray:
    """The sweep values as an array, after checking them and the parameter's name."""
    values = np.asarray(values, dtype=float)
    if values.ndim != 1 or values.size == 0 or not np.all(np.isfinite(values)):
        raise ValueError("sweep values must be a non-empty list of finite numbers")
    try:
        system.with_values(**{parameter: float(values[0])})  # an unknown name fails here
    except KeyError as err:
        raise ValueError(err.args[0]) from None
    return values


@dataclass(frozen=True)
class _Chain:
    """One worker task: a continuation chain, or a single independent point.

    ``indices`` are the points' positions in the sweep's order; with a ``store`` each
    finished point is written there at once (atomically), so nothing computed is lost.
    """

    module: str
    base_values: dict
    parameter: str
    values: list
    x0: list | None
    settings: dict
    continuation: bool
    indices: list = field(default_factory=list)
    store: str | None = None


def _run_chain(chain: _Chain, on_point=None) -> list[SweepPoint]:
    system = System.load(chain.module, **chain.base_values)
    state = None if chain.x0 is None else np.asarray(chain.x0, dtype=float)
    out = []
    for k, value in enumerate(chain.values):
        for attempt in (1, 2):  # a failed point is tried once more, then recorded
            try:
                point_system = system.with_values(**{chain.parameter: value})
                result = analyse_point(point_system, state, **chain.settings)
                point = SweepPoint.from_result(result, value)
                break
            except (SimulationError, ValueError, FloatingPointError) as err:
                point = SweepPoint.failed(system, value, err, attempt)
        if chain.store is not None:
            store_point(Path(chain.store), chain.indices[k], point)
        out.append(point)
        if chain.continuation and point.ok:
            state = np.asarray(point.x_final)
        if on_point is not None:
            on_point(point)
    return out


def _plan(
    system: System,
    parameter: str,
    values,
    *,
    continuation: bool,
    backward: bool,
    x0,
    settings: dict,
    done: dict[int, SweepPoint] | None = None,
    store: Path | None = None,
) -> list[_Chain]:
    values = _checked(system, parameter, values)
    order = [float(v) for v in (values[::-1] if backward else values)]
    x0 = None if x0 is None else [float(v) for v in x0]
    done = done or {}
    base = (module_ref(system), dict(system.values), parameter)
    where = None if store is None else str(store)
    if continuation:
        # Resume after the last finished point, from the last state that was reached.
        k = 0
        while k in done:
            k += 1
        for j in range(k - 1, -1, -1):
            if done[j].ok:
                x0 = [float(v) for v in done[j].x_final]
                break
        if k == len(order):
            return []
        return [_Chain(*base, order[k:], x0, settings, True, list(range(k, len(order))), where)]
    return [
        _Chain(*base, [v], x0, settings, False, [i], where)
        for i, v in enumerate(order)
        if i not in done
    ]


def _execute(
    chains: list[_Chain],
    executor: str,
    workers: int | None,
    progress: Progress | None,
    scheduler: str | None = None,
) -> list[list[SweepPoint]]:
    if executor not in EXECUTORS:
        raise ValueError(f"unknown executor '{executor}'; executors: {', '.join(EXECUTORS)}")

    def tick(point):
        if progress:
            progress.step(f"{chains[0].parameter}={point.value:.4g}")

    if executor == "serial" or (executor == "processes" and len(chains) <= 1):
        # In this process: progress point by point, also inside a chain.
        return map_tasks(partial(_run_chain, on_point=tick), chains)

    def ticks(chunk):
        for point in chunk:
            tick(point)

    return map_tasks(
        _run_chain, chains, executor=executor, workers=workers, scheduler=scheduler, on_result=ticks
    )


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
    direction = ("backward" if backward else "forward") if continuation else "independent"
    x0_list = None if x0 is None else [float(v) for v in x0]
    values = _checked(system, parameter, values)  # before any folder is created
    done: dict[int, SweepPoint] = {}
    if store is not None:
        manifest = {
            "format": STORE_FORMAT,
            "model": system.name,
            "model_hash": system.model_hash,
            "parameter": parameter,
            "values": [float(v) for v in values],
            "direction": direction,
            "base_values": {k: float(v) for k, v in system.values.items()},
            "settings": json.loads(dumps(settings)),
            "x0": x0_list,
        }
        done = open_store(Path(store), manifest)
    chains = _plan(
        system,
        parameter,
        values,
        continuation=continuation,
        backward=backward,
        x0=x0,
        settings=settings,
        done=done,
        store=store,
    )
    if progress is not None:
        for _ in done:
            progress.step("(stored)")
    found = dict(done)
    for chain, points in zip(
        chains, _execute(chains, executor, workers, progress, scheduler), strict=True
    ):
        found.update(zip(chain.indices, points, strict=True))
    points = [found[i] for i in range(values.size)]
    if backward:
        points = points[::-1]
    return _result(system, parameter, values, direction, dict(settings, x0=x0_list), points)


@dataclass(frozen=True)
class SweepJob:
    """One continuation sweep of :func:`sweep_many`: ``settings`` go to analyse_point."""

    system: System
    parameter: str
    values: Sequence[float]
    backward: bool = False
    x0: Sequence[float] | None = None
    settings: dict = field(default_factory=dict)


def sweep_many(
    jobs: list[SweepJob],
    *,
    executor: str = "processes",
    workers: int | None = None,
    progress: Progress | None = None,
    scheduler: str | None = None,
) -> list[SweepResult]:
    """Several continuation sweeps run side by side, one chain per worker process."""
    plans = []
    for job in jobs:
        (chain,) = _plan(
            job.system,
            job.parameter,
            job.values,
            continuation=True,
            backward=job.backward,
            x0=job.x0,
            settings=dict(job.settings),
        )
        plans.append(chain)
    results = []
    for job, points in zip(
        jobs, _execute(plans, executor, workers, progress, scheduler), strict=True
    ):
        results.append(
            _result(
                job.system,
                job.parameter,
                job.values,
                "backward" if job.backward else "forward",
                dict(job.settings),
                points[::-1] if job.backward else points,
            )
        )
    return results


def module_ref(system: System) -> str:
    """How a worker process finds the model: its module name, or its file."""
    name = system.module.__name__
    if name.startswith("gearsym.generated."):
        return name.rsplit(".", 1)[-1]
    return system.module.__file__
