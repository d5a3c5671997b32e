"""The work units of a sweep: chains of points, planned here and run in a worker.

A chain is a continuation chain (each point from the previous point's end state), one
independent point, or -- with a compiled method -- a chunk of independent points that
run as one call of the lockstep engine (``simulate_many``: every point of the chunk
integrated together in C, then analysed as :func:`analyse_point` analyses a trajectory,
so a sweep point does not depend on the path it took, within the integrator's
tolerance).  Workers rebuild the system from the generated module's name, so nothing
unpicklable crosses processes; each finished point is written to the store at once.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..analysis.point import analyse_point, analyse_trajectory
from ..analysis.record import RunRecord
from ..integrate import SimulationError
from ..integrate.methods import get_method
from ..integrate.simulate import check_start, fastest_method, simulate_many
from ..system import System
from .store import RunStore, record_text

__all__ = ["Chain", "ChainDone", "checked_values", "module_ref", "plan", "run_chain"]

# Points of one lockstep chunk: the engine's group size (``run_batch(group=64)``).
CHUNK = 64
CHUNK_BYTES = 256 << 20  # and at most this much of samples per chunk (issue 14)
SPREAD = 4
_FAILURES = (SimulationError, ValueError, FloatingPointError)
# the settings that go to the integration, and those that go to the analysis
_SIMULATE = (
    *("method", "rtol", "atol", "transient", "periods", "samples_per_period"),
    *("steps_per_period", "on_invalid", "transient_rtol"),
)
_ANALYSE = ("rtol", "atol", "lyapunov_periods", "steps_per_period", "on_invalid")
_ANALYSE += ("budget",)


@dataclass(frozen=True)
class Chain:
    """One worker task: a continuation chain, one independent point, or a lockstep chunk
    of independent points (``batch``).

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
    store: RunStore | None = None
    batch: bool = False
    continued: bool = False  # x0 is an earlier point's end state (a resumed chain)


@dataclass(frozen=True)
class ChainDone:
    """A chain's points in its order, with each point's stored JSON text (None without a
    store), so that the sweep's file is assembled without encoding the points again."""

    points: list
    texts: list


def module_ref(system: System) -> str:
    """How a worker process finds the model: its module name, or its file."""
    name = system.module.__name__
    if name.startswith("gearsym.generated."):
        return name.rsplit(".", 1)[-1]
    return system.module.__file__


def checked_values(system: System, parameter: str, values, x0=None) -> np.ndarray:
    """The sweep values as an array, after checking them and the parameter's name."""
    values = np.asarray(values, dtype=float)
    if values.ndim != 1 or values.size == 0 or not np.all(np.isfinite(values)):
        raise ValueError("sweep values must be a non-empty list of finite numbers")
    # Every value once through the model's own checks (an unknown name, a limit, a
    # negative stiffness) and, from the default start, the force law's valid range.
    for v in values[:1] if values.size > 4096 else values:
        try:
            point = system.with_values(**{parameter: float(v)})
            if x0 is None:
                check_start(point)
        except KeyError as err:
            raise ValueError(err.args[0]) from None
        except ValueError as err:
            raise ValueError(f"{parameter} = {v:g}: {err}") from None
    return values


def _start(state, continued: bool) -> dict:
    """Where a point starts, as its record says it."""
    if state is None:
        return {"start": "default"}
    return {"start": "continued" if continued else "given", "x0": np.array(state, dtype=float)}


def _one(
    system: System, parameter: str, value: float, state, settings: dict, continued=False
) -> RunRecord:
    """One point by :func:`analyse_point`; a failure is tried once more, then recorded."""
    values, start = {parameter: value}, _start(state, continued)
    for attempt in (1, 2):
        try:
            result = analyse_point(system.with_values(**values), state, **settings)
            return result.record(values, **start)
        except _FAILURES as err:
            point = RunRecord.failed(system, values, err, attempt, **start)
    return point


def _batch(chain: Chain, system: System):
    """The points of a chunk, integrated together (None: the engine refused the chunk,
    then the points run one by one); each is analysed as the worker goes, and a point
    whose analysis fails goes the per-point way, like any failed point."""
    systems = [system.with_values(**{chain.parameter: v}) for v in chain.values]
    state = None if chain.x0 is None else np.asarray(chain.x0, dtype=float)
    sim = {k: v for k, v in chain.settings.items() if k in _SIMULATE}
    rest = {k: v for k, v in chain.settings.items() if k in _ANALYSE}
    try:
        trajectories = simulate_many(
            systems, None if state is None else [state] * len(systems), **sim
        )
    except _FAILURES:
        return None

    def analysed(value, tr):
        try:
            record = analyse_trajectory(tr, **rest).record
            return record({chain.parameter: value}, **_start(state, False))
        except _FAILURES:
            return _one(system, chain.parameter, value, state, chain.settings)

    return map(analysed, chain.values, trajectories)


def _points(chain: Chain, system: System):
    if chain.batch:
        points = _batch(chain, system)
        if points is not None:
            yield from points
            return
    state = None if chain.x0 is None else np.asarray(chain.x0, dtype=float)
    continued = chain.continued
    for value in chain.values:
        point = _one(system, chain.parameter, value, state, chain.settings, continued)
        if chain.continuation and point.ok:
            state, continued = np.asarray(point.x_final), True
        yield point


def run_chain(chain: Chain, on_point=None) -> ChainDone:
    """Run one chain (in a worker): its points, each stored as soon as it is done (a
    lockstep chunk, whose points finish together, as one file)."""
    system = System.load(chain.module, **chain.base_values)
    points, texts = [], []
    for k, point in enumerate(_points(chain, system)):
        text = None
        if chain.store is not None and chain.batch:
            text = record_text(point)
        elif chain.store is not None:
            text = chain.store.append({chain.indices[k]: point})[chain.indices[k]]
        points.append(point)
        texts.append(text)
        if on_point is not None:
            on_point(point)
    if chain.store is not None and chain.batch:
        records = dict(zip(chain.indices, points, strict=True))
        chain.store.append(records, dict(zip(chain.indices, texts, strict=True)))
    return ChainDone(points, texts)


def plan(
    system: System,
    parameter: str,
    values,
    *,
    continuation: bool,
    backward: bool,
    x0,
    settings: dict,
    done: dict[int, RunRecord] | None = None,
    store: RunStore | None = None,
) -> list[Chain]:
    """The chains of a sweep, without the points already ``done`` (from the store)."""
    values = checked_values(system, parameter, values, x0)
    order = [float(v) for v in (values[::-1] if backward else values)]
    x0 = None if x0 is None else [float(v) for v in x0]
    done = done or {}
    base = (module_ref(system), dict(system.values), parameter)
    where = store
    if continuation:
        # Resume after the last finished point, from the last state that was reached.
        k = 0
        while k in done:
            k += 1
        continued = False
        for j in range(k - 1, -1, -1):
            if done[j].ok:
                x0, continued = [float(v) for v in done[j].x_final], True
                break
        if k == len(order):
            return []
        rest = list(range(k, len(order)))
        return [Chain(*base, order[k:], x0, settings, True, rest, where, continued=continued)]
    todo = [i for i in range(len(order)) if i not in done]
    method = settings.get("method") or fastest_method(settings.get("rtol", 1e-8))
    if get_method(method).family != "native" or len(order) < 2:
        return [Chain(*base, [order[i]], x0, settings, False, [i], where) for i in todo]
    # Compiled methods: lockstep chunks of up to CHUNK points, as many as a multiple of
    # SPREAD so that 2 or 4 workers share the work evenly.  The chunks follow from the
    # number of points alone (not from the executor, the machine or what a resumed store
    # holds), so that a sweep's results are the same bits whichever way it runs; a
    # resumed sweep runs the chunks that are not done.
    # A chunk's samples stay within CHUNK_BYTES: long runs take fewer points per chunk.
    samples = settings.get("periods", 100) * settings.get("samples_per_period", 64) + 1
    size = max(1, min(CHUNK, CHUNK_BYTES // (8 * system.n * samples)))
    count = -(-max(1, -(-len(order) // size)) // SPREAD) * SPREAD
    chunks = np.array_split(np.arange(len(order)), min(count, len(order)))
    chunks = [c for c in chunks if c.size and any(int(i) not in done for i in c)]
    return [
        Chain(*base, [order[i] for i in c], x0, settings, False, c.tolist(), where, True)
        for c in chunks
        if c.size
    ]
