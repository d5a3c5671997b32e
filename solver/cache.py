"""The one cache root of gearsym: ``$GEARSYM_CACHE``, else ``$XDG_CACHE_HOME/gearsym``,
else ``~/.cache/gearsym``.  Compiled libraries go to ``native/`` below it, models derived
from a user's scene files to ``models/``.

A root that cannot be written (read-only, a file in the way, a full disk) is replaced by
a folder under the system's temporary directory, with one warning naming both: the work
goes on, only the cache does not outlive the machine's next clean-up.
"""

from __future__ import annotations

import os
import tempfile
import warnings
from pathlib import Path

__all__ = ["cache_root"]

_checked: dict[Path, Path] = {}


def cache_root() -> Path:
    env = os.environ.get("GEARSYM_CACHE")
    if env:
        wanted = Path(env)
    else:
        base = os.environ.get("XDG_CACHE_HOME") or (Path.home() / ".cache")
        wanted = Path(base) / "gearsym"
    if wanted not in _checked:
        _checked[wanted] = _usable(wanted)
    return _checked[wanted]


def _usable(wanted: Path) -> Path:
    why = _unwritable(wanted)
    if why is None:
        return wanted
    user = os.getuid() if hasattr(os, "getuid") else "user"
    fallback = Path(tempfile.gettempdir()) / f"gearsym-cache-{user}"
    if _unwritable(fallback) is not None:
        fallback = Path(tempfile.mkdtemp(prefix="gearsym-cache-"))
    warnings.warn(
        f"the cache {wanted} cannot be written ({why}); using {fallback} instead "
        "(set GEARSYM_CACHE to a writable folder to keep compiled models)",
        stacklevel=3,
    )
    return fallback


def _unwritable(folder: Path) -> str | None:
    """Why ``folder`` cannot hold the cache, or None."""
    try:
        folder.mkdir(parents=True, exist_ok=True)
        probe = folder / f".probe-{os.getpid()}"
        probe.write_bytes(b"")
        probe.unlink()
    except OSError as err:
        return err.strerror or str(err)
    return None
