"""The one cache root of gearsym: ``$GEARSYM_CACHE``, else ``$XDG_CACHE_HOME/gearsym``,
else ``~/.cache/gearsym``.  Compiled libraries go to ``native/`` below it, models derived
from a user's scene files to ``models/``.

A root that cannot be written (read-only, a file in the way, a full disk) is replaced by
a folder under the system's temporary directory, with one warning naming both: the work
goes on, only the cache does not outlive the machine's next clean-up.  That folder is
used only when it is the user's own and no one else may write it (``/tmp`` is shared: a
folder another user made there first, or a link, is passed over for a fresh private one).

What lies in the cache runs with the user's rights: a model is imported as Python, a
library loaded as machine code.  The resolver (``gearsym/resolve.py``) imports a cached
model only when its bytes hash to the digest written beside it; that guards against
corruption, not against someone who can already write the user's files
(``docs/user-guide.md``, "Who can write the cache").
"""

from __future__ import annotations

import contextlib
import os
import stat
import tempfile
import warnings
from pathlib import Path

__all__ = ["cache_root", "locked"]

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
    if not _private(fallback) or _unwritable(fallback) is not None:
        fallback = Path(tempfile.mkdtemp(prefix="gearsym-cache-"))
    warnings.warn(
        f"the cache {wanted} cannot be written ({why}); using {fallback} instead "
        "(set GEARSYM_CACHE to a writable folder to keep compiled models)",
        stacklevel=3,
    )
    return fallback


def _private(folder: Path) -> bool:
    """Whether ``folder`` (made now if missing, for this user only) is a real folder of
    this user that no one else may write."""
    if not hasattr(os, "getuid"):
        return True
    try:
        folder.mkdir(mode=0o700, exist_ok=True)
        st = folder.lstat()
    except OSError:
        return False
    return (
        stat.S_ISDIR(st.st_mode)
        and st.st_uid == os.getuid()
        and not st.st_mode & (stat.S_IWGRP | stat.S_IWOTH)
    )


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


@contextlib.contextmanager
def locked(path: Path):
    """Hold an exclusive lock on ``<path>.lock`` (POSIX ``flock``) while a cache file is
    built, so that processes needing it at once build it once.  A platform without
    ``flock``, a cache one may read but not write, or a file system without locks (NFS
    without its lock service, say) goes without: the builders' atomic renames keep that
    safe, only the work may be done twice."""
    fh = None
    try:
        import fcntl

        path.parent.mkdir(parents=True, exist_ok=True)
        fh = open(path.with_name(path.name + ".lock"), "a")  # noqa: SIM115 - held across yield
        fcntl.flock(fh, fcntl.LOCK_EX)
    except (ImportError, OSError):
        if fh is not None:
            fh.close()
        fh = None
    try:
        yield
    finally:
        if fh is not None:
            fh.close()  # releases the lock
