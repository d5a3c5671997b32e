"""The progress line of long runs, on stderr: one line per stage, "k of N" and the time left.

On a terminal the line is redrawn in place (``\\r``); elsewhere (CI, a pipe, a log file) a
line is written at most once per tenth of the stage, and at its end, so that logs stay
short.  The time left is extrapolated from the pace of the items done so far, counted from
the first one's end: what comes before it (compiling, a pool starting, the first long
task) is paid once, not per item; so it is said from the second report on.
:class:`Stages` numbers the stages of one command and keeps how long each took.
"""

from __future__ import annotations

import sys
import time

__all__ = ["Progress", "Stages", "fmt_seconds"]

_WIDTH = 120  # a redrawn line is padded to this, so a shorter one wipes a longer


def fmt_seconds(seconds: float) -> str:
    """``'42 s'`` or ``'3 min 05 s'``."""
    s = int(round(seconds))
    return f"{s} s" if s < 60 else f"{s // 60} min {s % 60:02d} s"


class Progress:
    """A progress line: ``label: k of N, 12 s, about 30 s left  note``.

    Parameters
    ----------
    total : int
        Items in the stage (sweep points, tasks, maps, figures).
    label : str
        What the stage does.
    stream : file, optional
        Default ``sys.stderr``.
    enabled : bool
        False: count only (``done``, ``elapsed``), write nothing.
    after : str
        What the stage still does once its items are done (said with the last item), so
        that a line at "N of N" does not look stuck.
    """

    def __init__(
        self, total: int, label: str, stream=None, enabled: bool = True, clock=None, after=""
    ):
        self.total, self.label, self.done = int(total), label, 0
        self.after = after
        self.stream = stream or sys.stderr
        self.enabled = enabled
        self.tty = hasattr(self.stream, "isatty") and self.stream.isatty()
        self._clock = clock or time.perf_counter
        self.started = self._clock()
        self._last_tenth = -1
        self._first: tuple[float, int] | None = None  # (time, items) at the first report
        self._finished = False

    @property
    def elapsed(self) -> float:
        return self._clock() - self.started

    def left(self) -> float | None:
        """Seconds left at the pace since the first report (None until a second one)."""
        if self._first is None or self.done <= self._first[1]:
            return None
        t0, n0 = self._first
        pace = (self._clock() - t0) / (self.done - n0)
        return pace * max(self.total - self.done, 0)

    def line(self, note: str = "") -> str:
        left = self.left()
        eta = "" if left is None or self.done >= self.total else f", about {fmt_seconds(left)} left"
        text = f"{self.label}: {self.done} of {self.total}, {fmt_seconds(self.elapsed)}{eta}"
        return f"{text}  {note}" if note else text

    def step(self, note: str = "", n: int = 1) -> None:
        """``n`` more items done (``note``: what the last one was)."""
        self.done = min(self.done + n, self.total)
        if self._first is None:
            self._first = (self._clock(), self.done)
        if not self.enabled or self._finished:
            return
        end = self.done >= self.total
        tenth = int(10 * self.done / max(self.total, 1))
        if end and self.after:
            note = f"{note}; {self.after}" if note else self.after
        if self.tty:
            self.stream.write("\r" + self.line(note)[:_WIDTH].ljust(_WIDTH) + "\n" * end)
        elif tenth != self._last_tenth or end:
            self.stream.write(self.line(note) + "\n")
            self._last_tenth = tenth
        self._finished = end
        self.stream.flush()

    def __call__(self, _result=None) -> None:
        """One item done: usable as ``map_tasks(..., on_result=progress)``."""
        self.step()

    def finish(self, note: str = "") -> float:
        """End the stage's line (items not counted are taken as done); its seconds."""
        if self.enabled and not self._finished:
            self.done = self.total
            if self.tty:
                self.stream.write("\r" + self.line(note)[:_WIDTH].ljust(_WIDTH) + "\n")
            else:
                self.stream.write(self.line(note) + "\n")
            self.stream.flush()
        self._finished = True
        return self.elapsed


class Stages:
    """The numbered stages of one command, each a :class:`Progress` line
    (``reproduce 3 of 9, operating points: 5 of 20, ...``), and how long each took.

    ``stage(name, total)`` ends the stage before it and starts the next; ``end()`` ends
    the last.  ``times`` lists ``(name, seconds)`` of the stages ended.
    """

    def __init__(self, count: int, label: str, stream=None, enabled: bool = True):
        self.count, self.label, self.stream, self.enabled = count, label, stream, enabled
        self.times: list[tuple[str, float]] = []
        self.current: Progress | None = None
        self._name = ""

    def stage(self, name: str, total: int, after: str = "") -> Progress:
        self.end()
        k = len(self.times) + 1
        self._name = name
        self.current = Progress(
            total,
            f"{self.label} {k} of {self.count}, {name}",
            self.stream,
            self.enabled,
            after=after,
        )
        return self.current

    def end(self) -> None:
        if self.current is not None:
            self.times.append((self._name, self.current.finish()))
            self.current = None
