"""The one cache root of gearsym: ``$GEARSYM_CACHE``, else ``$XDG_CACHE_HOME/gearsym``,
else ``~/.cache/gearsym``.  Compiled libraries go to ``native/`` below it, models derived
from a user's scene files to ``models/``."""

from __future__ import annotations

import os
from pathlib import Path

__all__ = ["cache_root"]


def cache_root() -> Path:
    env = os.environ.get("GEARSYM_CACHE")
    if env:
        return Path(env)
    base = os.environ.get("XDG_CACHE_HOME") or (Path.home() / ".cache")
    return Path(base) / "gearsym"
