"""Sweeps: bifurcation diagrams with continuation, their resumable store, one executor.

* ``sweep.py`` -- :func:`sweep` and :func:`sweep_many`, :class:`SweepResult`;
* ``points.py`` -- :class:`SweepPoint`, the typed summary of one point;
* ``store.py`` -- the per-point store that makes sweeps resumable;
* ``executor.py`` -- serial, local processes or dask.distributed, for every caller;
* ``progress.py`` -- the progress line.
"""

from ..executor import EXECUTORS, map_tasks
from .points import Extremes, SweepPoint
from .progress import Progress
from .store import SweepStoreError
from .sweep import SweepJob, SweepResult, module_ref, sweep, sweep_many

__all__ = [
    "EXECUTORS",
    "Extremes",
    "Progress",
    "SweepJob",
    "SweepPoint",
    "SweepResult",
    "SweepStoreError",
    "map_tasks",
    "module_ref",
    "sweep",
    "sweep_many",
]
