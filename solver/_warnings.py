"""Warning classes that more than one room of ``solver/`` names (the ground floor)."""

from __future__ import annotations

__all__ = ["NativeFallback"]


class NativeFallback(UserWarning):
    """A run goes without the compiled library (no compiler, or a build that failed).

    Worker processes ignore it (``solver/executor.py``): the parent process decides once
    and says it once (``run.decide_backend``, ``sweep._decide_native``)."""
