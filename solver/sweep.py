"""Parameter sweeps: bifurcation diagrams and two-parameter maps.

A sweep runs :func:`analyse_point` over the values of one named parameter (a scene
parameter such as ``lambda`` or ``f1``, or a model parameter).  With continuation each
point starts from the previous point's final state, forward or backward, so that
coexisting attractors show up as hysteresis; without it every point starts from the same
state and points are independent, so they run in parallel.

Executors: ``serial`` or ``processes`` (local worker processes, default all cores).
Workers rebuild the system from the generated module's name, so nothing unpicklable
crosses processes, and every point's result is a plain dictionary.
"""

from __future__ import annotations

import json
import os
import sys
import time
from collections.abc import Sequence
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ._json import dumps
from .point import analyse_point
from .simulate import SimulationError
from .system import System

__all__ = ["Progress", "SweepResult", "SweepStoreError", "sweep", "sweep_many"]

EXECUTORS = ("serial", "processes", "dask")


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
    points: list = field(default_factory=list)  # dicts, see _summary
    scales: dict = field(default_factory=dict)  # omega_n and half backlash: back to SI

    def poincare(self, state: str) -> list[np.ndarray]:
        return [np.asarray(p["poincare"][state]) for p in self.points]

    def motion(self, coordinate: str) -> list[str]:
        return [p["classification"][coordinate]["motion"] for p in self.points]

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
            "points": self.points,
        }

    def save(self, path: Path) -> Path:
        """Write the sweep as JSON (parameter values, scales and model hash included)."""
        path = Path(path)
        path.parent.mkdir(parents=True, exist_ok=True)
        tmp = path.with_suffix(path.suffix + ".tmp")
        tmp.write_text(dumps(self.to_dict()), encoding="utf-8")
        os.replace(tmp, path)
        return path

    @classmethod
    def load(cls, path: Path) -> SweepResult:
        d = json.loads(Path(path).read_text(encoding="utf-8"))
        return cls(d["model"], d["model_hash"], d["parameter"], np.asarray(d["values"]),
                   d["direction"], d["base_values"], d["settings"], d["points"],
                   d.get("scales", {}))  # fmt: skip


class Progress:
    """A plain progress line on stderr: redrawn in place on a terminal, every 10 % else."""

    def __init__(self, total: int, label: str, stream=None, enabled: bool = True):
        self.total, self.label, self.done = total, label, 0
        self.stream = stream or sys.stderr
        self.enabled = enabled
        self.tty = hasattr(self.stream, "isatty") and self.stream.isatty()
        self.started = time.perf_counter()
        self._last_decile = -1

    def step(self, note: str = "") -> None:
        self.done += 1
        if not self.enabled:
            return
        frac = self.done / max(self.total, 1)
        elapsed = time.perf_counter() - self.started
        bar = "#" * int(30 * frac) + "." * (30 - int(30 * frac))
        line = f"{self.label} [{bar}] {self.done}/{self.total} {elapsed:6.1f} s {note}"
        if self.tty:
            end = "\n" if self.done == self.total else ""
            self.stream.write("\r" + line[:120].ljust(120) + end)
        elif int(10 * frac) != self._last_decile or self.done == self.total:
            self._last_decile = int(10 * frac)
            self.stream.write(line + "\n")
        self.stream.flush()


def _summary(result, value: float) -> dict:
    d = result.describe(poincare=True)
    return {
        "value": float(value),
        "status": d["integration"]["status"],
        "classification": d["classification"],
        "extremes": d["extremes"],
        "meshing_states": d["meshing_states"],
        "lyapunov": d["lyapunov"],
        "spectra": d["spectra"],
        "poincare": d["poincare"],
        "x_final": result.trajectory.x_final.tolist(),
        "integration": d["integration"],
    }


def _failed(system: System, value: float, error: Exception) -> dict:
    """A point whose integration failed: recorded with its error, never dropped."""
    return {
        "value": float(value),
        "status": "failed",
        "error": str(error),
        "classification": {
            c: {"motion": "failed", "period": None, "evidence": {"error": str(error)}}
            for c in system.coordinates
        },  # fmt: skip
        "extremes": {s: {"max": None, "min": None} for s in system.states},
        "meshing_states": {},
        "lyapunov": None,
        "spectra": {},
        "poincare": {s: [] for s in system.states},
        "x_final": None,
        "integration": {},
    }


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


def _run_chain(chain: _Chain, on_point=None) -> list[dict]:
    system = System.load(chain.module, **chain.base_values)
    state = None if chain.x0 is None else np.asarray(chain.x0, dtype=float)
    out = []
    for k, value in enumerate(chain.values):
        for attempt in (1, 2):  # a failed point is tried once more, then recorded
            try:
                point_system = system.with_values(**{chain.parameter: value})
                point = _summary(analyse_point(point_system, state, **chain.settings), value)
                break
            except (SimulationError, ValueError, FloatingPointError) as err:
                point = _failed(system, value, err)
                point["attempts"] = attempt
        if chain.store is not None:
            store_point(Path(chain.store), chain.indices[k], point)
        out.append(point)
        if chain.continuation and point["status"] == "ok":
            state = np.asarray(point["x_final"])
        if on_point is not None:
            on_point(point)
    return out


class SweepStoreError(ValueError):
    """A sweep folder that cannot be resumed (another model, or another sweep)."""


STORE_FORMAT = 1


def store_point(store: Path, index: int, point: dict) -> None:
    """Write one finished point atomically (temporary file, then rename)."""
    folder = store / "points"
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / f"{index:05d}.json"
    tmp = folder / f".{index:05d}.json.{os.getpid()}.tmp"
    tmp.write_text(dumps(point), encoding="utf-8")
    os.replace(tmp, path)


def _open_store(store: Path, manifest: dict) -> dict[int, dict]:
    """Create the store, or check that it holds this very sweep; return its points."""
    store.mkdir(parents=True, exist_ok=True)
    path = store / "manifest.json"
    if path.exists():
        old = json.loads(path.read_text(encoding="utf-8"))
        if old.get("model_hash") != manifest["model_hash"]:
            raise SweepStoreError(
                f"{store} was written by another model version (hash "
                f"{str(old.get('model_hash'))[:12]}, this model {manifest['model_hash'][:12]}); "
                "choose another output folder or delete it"
            )
        differs = [k for k in manifest if old.get(k) != manifest[k]]
        if differs:
            raise SweepStoreError(
                f"{store} holds another sweep ({', '.join(differs)} differ); choose another "
                "output folder or delete it"
            )
    else:
        tmp = store / ".manifest.json.tmp"
        tmp.write_text(dumps(manifest, indent=1), encoding="utf-8")
        os.replace(tmp, path)
    done = {}
    for f in sorted((store / "points").glob("[0-9]*.json")):
        try:
            done[int(f.stem)] = json.loads(f.read_text(encoding="utf-8"))
        except (ValueError, OSError):
            f.unlink(missing_ok=True)  # a torn file cannot exist (atomic writes); be safe
    return done


def _plan(system: System, parameter: str, values, *, continuation: bool, backward: bool,
          x0, settings: dict, done: dict | None = None,
          store: Path | None = None) -> list[_Chain]:  # fmt: skip
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
            if done[j].get("status") == "ok":
                x0 = done[j]["x_final"]
                break
        if k == len(order):
            return []
        return [_Chain(*base, order[k:], x0, settings, True, list(range(k, len(order))), where)]
    return [_Chain(*base, [v], x0, settings, False, [i], where)
            for i, v in enumerate(order) if i not in done]  # fmt: skip


def _execute(chains: list[_Chain], executor: str, workers: int | None,
             progress: Progress | None,
             scheduler: str | None = None) -> list[list[dict]]:  # fmt: skip
    if executor not in EXECUTORS:
        raise ValueError(f"unknown executor '{executor}'; executors: {', '.join(EXECUTORS)}")

    def tick(point):
        if progress:
            progress.step(f"{chains[0].parameter}={point['value']:.4g}")

    if executor == "dask":
        return _dask(chains, workers, tick, scheduler)
    if executor == "serial" or len(chains) <= 1:
        return [_run_chain(c, on_point=tick) for c in chains]
    results = []
    with ProcessPoolExecutor(max_workers=workers or os.cpu_count()) as pool:
        for chunk in pool.map(_run_chain, chains):
            results.append(chunk)
            for point in chunk:
                tick(point)
    return results


def _dask(chains, workers, tick, scheduler) -> list[list[dict]]:
    """Run the chains on a dask.distributed cluster: the scheduler at ``scheduler``
    (``tcp://host:port``), or a LocalCluster of ``workers`` single-threaded processes."""
    try:
        from dask.distributed import Client, LocalCluster, as_completed
    except ImportError:
        raise ValueError(
            "the dask executor needs dask.distributed: pip install 'gearsym[dask]'"
        ) from None
    cluster = None
    if scheduler:
        client = Client(scheduler)
    else:
        cluster = LocalCluster(n_workers=workers or os.cpu_count(), threads_per_worker=1,
                               processes=True, dashboard_address=None)  # fmt: skip
        client = Client(cluster)
    try:
        futures = client.map(_run_chain, chains, pure=False)
        index = {f.key: k for k, f in enumerate(futures)}
        results: list = [None] * len(chains)
        for future in as_completed(futures):
            chunk = future.result()
            results[index[future.key]] = chunk
            for point in chunk:
                tick(point)
        return results
    finally:
        client.close()
        if cluster is not None:
            cluster.close()


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
        scales=_scales(system),
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
    done: dict[int, dict] = {}
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
        done = _open_store(Path(store), manifest)
    chains = _plan(system, parameter, values, continuation=continuation, backward=backward,
                   x0=x0, settings=settings, done=done, store=store)  # fmt: skip
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


def sweep_many(jobs: list[dict], *, executor: str = "processes", workers: int | None = None,
               progress: Progress | None = None,
               scheduler: str | None = None) -> list[SweepResult]:  # fmt: skip
    """Several continuation sweeps (each a dict of :func:`sweep` arguments, ``system``
    included) run side by side, one chain per worker process."""
    plans = []
    for job in jobs:
        settings = _job_settings(job)
        (chain,) = _plan(
            job["system"],
            job["parameter"],
            job["values"],
            continuation=True,
            backward=job.get("backward", False),
            x0=job.get("x0"),
            settings=settings,
        )  # fmt: skip
        plans.append(chain)
    results = []
    for job, points in zip(
        jobs, _execute(plans, executor, workers, progress, scheduler), strict=True
    ):
        backward = job.get("backward", False)
        results.append(_result(job["system"], job["parameter"], job["values"],
                               "backward" if backward else "forward", _job_settings(job),
                               points[::-1] if backward else points))  # fmt: skip
    return results


def _scales(system: System) -> dict:
    return {"omega_n_rad_per_s": float(system.module.OMEGA_N),
            "half_backlash_m": dict(system.module.HALF_BACKLASH),
            "time": "tau = omega_n t; coordinates in half backlashes"}  # fmt: skip


def _job_settings(job: dict) -> dict:
    """The analyse_point settings of a sweep job (everything but what defines the sweep)."""
    return {k: v for k, v in job.items() if k not in ("system", "parameter", "values",
                                                       "backward", "x0")}  # fmt: skip


def module_ref(system: System) -> str:
    """How a worker process finds the model: its module name, or its file."""
    name = system.module.__name__
    if name.startswith("gearsym.generated."):
        return name.rsplit(".", 1)[-1]
    return system.module.__file__
