"""A thread that writes result files beside the stages of ``gearsym reproduce``."""

from __future__ import annotations

from concurrent.futures import ThreadPoolExecutor

__all__ = ["Writer"]


class Writer:
    """One thread beside the stages for what only the main process did while both
    workers waited for it: the result files of the sweeps and responses (their MATLAB
    files alone took 2 to 3 s) and a derivation the report needs.  Each file is written
    atomically (``export.write_atomic``); :meth:`finish` waits for every one and raises
    the first error."""

    def __init__(self):
        self._pool = ThreadPoolExecutor(1, thread_name_prefix="gearsym-writer")
        self._pending: list = []

    def submit(self, fn, *args):
        future = self._pool.submit(fn, *args)
        self._pending.append(future)
        return future

    def wait(self) -> None:
        """Wait for everything submitted so far (its first error raised)."""
        pending, self._pending = self._pending, []
        for future in pending:
            future.result()

    def finish(self) -> None:
        try:
            self.wait()
        finally:
            self._pool.shutdown(wait=True)
