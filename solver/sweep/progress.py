"""A plain progress line on stderr for long runs."""

from __future__ import annotations

import sys
import time

__all__ = ["Progress"]


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
