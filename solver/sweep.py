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

from .point import analyse_point
from .system import System

__all__ = ["SweepResult", "sweep", "sweep_many", "Progress"]

EXECUTORS = ("serial", "processes")


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
        tmp.write_text(json.dumps(self.to_dict()), encoding="utf-8")
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


def _run_chain(task) -> list[dict]:
    """Worker: one continuation chain (or one independent point) of a sweep."""
    module, base_values, parameter, values, x0, settings, continuation = task
    system = System.load(module, **base_values)
    out = []
    state = None if x0 is None else np.asarray(x0, dtype=float)
    for value in values:
        sys_k = system.with_values(**{parameter: value})
        result = analyse_point(sys_k, state, **settings)
        out.append(_summary(result, value))
        if continuation and result.trajectory.status == "ok":
            state = result.trajectory.x_final
    return out


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
    **settings,
) -> SweepResult:
    """Sweep ``parameter`` over ``values`` (see module docstring); ``settings`` go to
    :func:`analyse_point` (method, rtol, transient, periods, ...)."""
    if executor not in EXECUTORS:
        raise ValueError(f"unknown executor '{executor}'; executors: {', '.join(EXECUTORS)}")
    values = np.asarray(values, dtype=float)
    system.with_values(**{parameter: float(values[0])})  # fails early on an unknown name
    order = values[::-1] if backward else values
    task_base = (module_ref(system), dict(system.values), parameter)
    if continuation:
        tasks = [(*task_base, list(order), x0, settings, True)]
    else:
        tasks = [(*task_base, [v], x0, settings, False) for v in order]
    points: list[dict] = []
    if executor == "serial" or len(tasks) == 1:
        for task in tasks:
            if continuation:
                # Step through the chain one point at a time to report progress.
                state = task[4]
                for v in task[3]:
                    (pt,) = _run_chain((*task_base, [v], state, settings, True))
                    points.append(pt)
                    state = pt["x_final"] if pt["status"] == "ok" else state
                    if progress:
                        progress.step(f"{parameter}={v:.4g}")
            else:
                points.extend(_run_chain(task))
                if progress:
                    progress.step(f"{parameter}={task[3][0]:.4g}")
    else:
        with ProcessPoolExecutor(max_workers=workers or os.cpu_count()) as pool:
            for chunk in pool.map(_run_chain, tasks):
                points.extend(chunk)
                if progress:
                    progress.step(f"{parameter}={chunk[0]['value']:.4g}")
    if backward:
        points = points[::-1]
    return SweepResult(
        model=system.name,
        model_hash=system.model_hash,
        parameter=parameter,
        values=values,
        direction=("backward" if backward else "forward") if continuation else "independent",
        base_values={k: float(v) for k, v in system.values.items()},
        settings={k: v for k, v in settings.items()},
        points=points,
        scales=_scales(system),
    )


def sweep_many(
    jobs: list[dict],
    *,
    executor: str = "processes",
    workers: int | None = None,
    progress: Progress | None = None,
) -> list[SweepResult]:
    """Run several sweeps (each a dict of :func:`sweep` arguments, ``system`` included);
    continuation chains run side by side in worker processes."""
    if executor == "serial":
        return [sweep(progress=progress, **job) for job in jobs]
    tasks = []
    for job in jobs:
        system = job["system"]
        values = np.asarray(job["values"], dtype=float)
        backward = job.get("backward", False)
        order = values[::-1] if backward else values
        settings = _job_settings(job)
        tasks.append((module_ref(system), dict(system.values),
                      job["parameter"], list(order), job.get("x0"), settings, True))  # fmt: skip
    results = []
    with ProcessPoolExecutor(max_workers=workers or os.cpu_count()) as pool:
        for job, chunk in zip(jobs, pool.map(_run_chain, tasks), strict=True):
            backward = job.get("backward", False)
            if backward:
                chunk = chunk[::-1]
            system = job["system"]
            settings = _job_settings(job)
            results.append(SweepResult(
                system.name, system.model_hash, job["parameter"],
                np.asarray(job["values"], dtype=float),
                "backward" if backward else "forward",
                {k: float(v) for k, v in system.values.items()}, settings, chunk,
                _scales(system),
            ))  # fmt: skip
            if progress:
                for _ in chunk:
                    progress.step()
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
