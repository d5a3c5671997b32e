"""The one executor: run independent tasks serially, on local processes, or on a
dask.distributed cluster, and hand back their results in the order of the tasks.

Sweeps, studies and the native batch runner all go through :func:`map_tasks`; each task
is a picklable value and ``fn`` a module-level function, so nothing unpicklable crosses
processes.  Local workers end with the process that started them, however it ends
(SIGKILL, SIGTERM, Ctrl-C): none is left behind to finish its tasks alone.
"""

from __future__ import annotations

import ctypes
import os
import signal
import sys
import threading
import time
from collections.abc import Callable, Sequence
from contextlib import contextmanager

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
    return _pool(fn, tasks, workers, on_result)


def _pool(fn, tasks, workers, on_result) -> list:
    """The local process pool; its workers end with this process however it ends."""
    import multiprocessing
    from concurrent.futures import ProcessPoolExecutor

    context = multiprocessing.get_context()
    # A worker's parent is this process (fork, spawn), or under forkserver the server,
    # whose pid is not known here (it ends when this process does, and its workers then).
    parent = None if context.get_start_method() == "forkserver" else os.getpid()
    pool = ProcessPoolExecutor(
        max_workers=workers or os.cpu_count(),
        mp_context=context,
        initializer=_bind_to_parent,
        initargs=(parent,),
    )
    results = []
    try:
        # The workers start here.  Ctrl-C reaches the whole process group, and a worker
        # struck before its initializer ignores SIGINT would print a KeyboardInterrupt
        # traceback of its own: SIGINT stays blocked while they start (they inherit the
        # mask, and unblock it once they ignore it); here a Ctrl-C waits till then.
        with _sigint_blocked():
            futures = [pool.submit(fn, task) for task in tasks]
        for future in futures:
            result = future.result()
            results.append(result)
            if on_result is not None:
                on_result(result)
    except BaseException as err:
        if not isinstance(err, Exception) or isinstance(err, BrokenPipeError):
            # Ctrl-C, an exit or a closed output: stop now, not after the running tasks
            # (a chain of a sweep can take minutes); what they stored so far stays.
            _kill_workers(pool)
        raise
    finally:
        pool.shutdown(wait=True, cancel_futures=True)
    return results


@contextmanager
def _sigint_blocked():
    """SIGINT held pending in this thread (where the OS can block it) inside the block."""
    block = getattr(signal, "pthread_sigmask", None)
    if block is None or threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = block(signal.SIG_BLOCK, {signal.SIGINT})
    try:
        yield
    finally:
        block(signal.SIG_SETMASK, previous)


def _kill_workers(pool) -> None:
    # Python 3.14 has ProcessPoolExecutor.kill_workers; before it, the pool's own table.
    kill = getattr(pool, "kill_workers", None)
    if kill is not None:
        kill()
        return
    for process in list((getattr(pool, "_processes", None) or {}).values()):
        try:
            process.kill()
        except (OSError, ValueError):
            pass  # already gone or already reaped


_PR_SET_PDEATHSIG = 1  # <linux/prctl.h>


def _bind_to_parent(parent: int | None) -> None:
    """Pool initializer: make this worker die with its parent, on any signal.

    On Linux the kernel sends SIGKILL to the worker when its parent ends
    (``prctl(PR_SET_PDEATHSIG)``); elsewhere a daemon thread polls the parent's pid.
    SIGKILL or SIGTERM of the parent would otherwise leave the workers under PID 1,
    finishing their tasks and then waiting forever for more.  Ctrl-C reaches the
    whole process group; only the parent acts on it (it kills the workers), so that a
    worker does not print a traceback of its own.
    """
    import warnings

    from ._warnings import NativeFallback

    # The parent said it once already (sweep._decide_native, run.decide_backend).
    warnings.simplefilter("ignore", NativeFallback)
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # discards a pending Ctrl-C too
    if hasattr(signal, "pthread_sigmask"):
        signal.pthread_sigmask(signal.SIG_UNBLOCK, {signal.SIGINT})
    _one_blas_thread()
    watched = os.getppid() if parent is None else parent
    if not _death_signal(signal.SIGKILL):
        threading.Thread(target=_watch_parent, args=(watched,), daemon=True).start()
    # The parent may have ended between the fork and the prctl: then nothing would come.
    if os.getppid() != watched:
        os._exit(1)


# OpenBLAS's setters under the names its builds export (plain, 64-bit integer, SciPy's)
_BLAS_THREADS = (
    "openblas_set_num_threads",
    "openblas_set_num_threads64_",
    "scipy_openblas_set_num_threads",
    "scipy_openblas_set_num_threads64_",
)


def _one_blas_thread() -> None:
    """One BLAS thread in this worker.  The pool has a worker per core already; each
    worker's OpenBLAS starting a thread per core as well made the small dense solves of
    harmonic balance and Newton (about 125 unknowns) wait on each other: 13x the CPU
    time of one thread per solve on 2 cores (issue 25, point 7).  A library it does not
    know (MKL, Accelerate) is left as it is."""
    os.environ["OPENBLAS_NUM_THREADS"] = "1"  # a library loaded later in this worker
    try:
        with open("/proc/self/maps", encoding="utf-8", errors="replace") as fh:
            paths = {line.split()[-1] for line in fh if "openblas" in line.lower()}
    except OSError:  # not Linux
        return
    for path in sorted(paths):
        try:
            lib = ctypes.CDLL(path)
        except OSError:
            continue
        for name in _BLAS_THREADS:
            setter = getattr(lib, name, None)
            if setter is not None:
                setter(1)


def _death_signal(signum: int) -> bool:
    """Ask the kernel for ``signum`` when the parent ends; False where it cannot."""
    if not sys.platform.startswith("linux"):
        return False
    try:
        libc = ctypes.CDLL(None, use_errno=True)
        return libc.prctl(_PR_SET_PDEATHSIG, int(signum), 0, 0, 0) == 0
    except (OSError, AttributeError):
        return False


def _watch_parent(parent: int) -> None:
    while os.getppid() == parent:
        time.sleep(0.5)
    os._exit(1)


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
