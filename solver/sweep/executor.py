"""The one executor: run independent tasks serially, on local processes, or on a
dask.distributed cluster, and hand back their results in the order of the tasks.

Sweeps, studies and the native batch runner all go through :func:`map_tasks`; each task
is a picklable value and ``fn`` a module-level function, so nothing unpicklable crosses
processes.
"""

from __future__ import annotations

import os
from collections.abc import Callable, Sequence

__all__ = ["EXECUTORS", "map_tasks"]

EXECUTORS = ("serial", "processes", "dask")


def map_tasks(
    fn: Callable,
    tasks: Sequence,
    *,
    executor: str = "serial",
    workers: int | None = None,
    scheduler: str | None = None,
    on_result: Callable | None = None,
) -> list:
    """``[fn(t) for t in tasks]``, run by ``executor``.

    Parameters
    ----------
    executor : {"serial", "processes", "dask"}
        ``processes``: a local pool of ``workers`` processes (default all cores);
        ``dask``: the scheduler at ``scheduler`` (``tcp://host:port``) or a LocalCluster
        of ``workers`` single-threaded processes.
    on_result : callable, optional
        Called with each result as it arrives (in task order except with dask).
    """
    if executor not in EXECUTORS:
        raise ValueError(f"unknown executor '{executor}'; executors: {', '.join(EXECUTORS)}")
    tasks = list(tasks)
    if executor == "dask":
        return _dask(fn, tasks, workers, scheduler, on_result)
    if executor == "serial" or len(tasks) <= 1:
        results = []
        for task in tasks:
            results.append(fn(task))
            if on_result is not None:
                on_result(results[-1])
        return results
    from concurrent.futures import ProcessPoolExecutor

    results = []
    with ProcessPoolExecutor(max_workers=workers or os.cpu_count()) as pool:
        for result in pool.map(fn, tasks):
            results.append(result)
            if on_result is not None:
                on_result(result)
    return results


def _dask(fn, tasks, workers, scheduler, on_result) -> list:
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
        cluster = LocalCluster(
            n_workers=workers or os.cpu_count(),
            threads_per_worker=1,
            processes=True,
            dashboard_address=None,
        )
        client = Client(cluster)
    try:
        futures = client.map(fn, tasks, pure=False)
        index = {f.key: k for k, f in enumerate(futures)}
        results: list = [None] * len(tasks)
        for future in as_completed(futures):
            result = future.result()
            results[index[future.key]] = result
            if on_result is not None:
                on_result(result)
        return results
    finally:
        client.close()
        if cluster is not None:
            cluster.close()
