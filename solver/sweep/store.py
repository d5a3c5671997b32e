"""The resumable sweep store: a manifest and the finished points, every file written
atomically (temporary file, then rename), so that nothing computed is lost and a torn
file cannot exist.

A point of a continuation chain, or an independent point run on its own, is one file
(``points/00012.json``) written as soon as it is done.  A lockstep chunk of independent
points (integrated together, so finished together) is one file
(``points/chunk-00048-50.json``: first index, number of points) holding the indices and
the points: creating 400 small files took 0.2 s of a 400-point sweep's CPU time.

One process writes into a store at a time (a lock the kernel frees when the process ends,
however it ends).  A point file that holds no valid point is moved to ``damaged/`` and
its points computed again; a damaged manifest is refused, as is one of another sweep.
"""

from __future__ import annotations

import json
import os
import time
import warnings
from pathlib import Path

import numpy as np

from .._json import dumps
from .points import SweepPoint

__all__ = [
    "STORE_FORMAT",
    "SweepStoreError",
    "close_store",
    "lock_store",
    "open_store",
    "point_text",
    "store_chunk",
    "store_point",
    "stored_count",
    "write_atomic",
]

STORE_FORMAT = 1


class SweepStoreError(ValueError):
    """A sweep folder that cannot be written or resumed: another model, another sweep, a
    damaged manifest, or another process writing into it."""


try:
    import fcntl
except ImportError:  # not POSIX: stores are not locked
    fcntl = None

_HELD: dict[Path, int] = {}  # store folder -> descriptor of its lock, held by this process


def lock_store(store: Path) -> None:
    """Lock ``store`` for this process, or refuse at once if another process holds it.

    The lock (``flock`` on ``store/lock``, which holds the holder's pid) lasts until
    :func:`close_store` or the end of the process, however it ends: the kernel frees it
    with the process (SIGKILL included) and its pool workers.  Locking a store this
    process holds already does nothing.
    """
    key = Path(store).resolve()
    if fcntl is None or key in _HELD:
        return
    key.mkdir(parents=True, exist_ok=True)
    path = key / "lock"
    fd = os.open(path, os.O_RDWR | os.O_CREAT, 0o644)
    try:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except BlockingIOError:
        holder = _holder(fd)
        os.close(fd)
        raise SweepStoreError(
            f"{store} is in use by another sweep (process {holder}); wait for it to finish "
            "or choose another --out"
        ) from None
    except OSError as err:  # a file system without locks (some network ones)
        os.close(fd)
        warnings.warn(
            f"{store} cannot be locked ({err.strerror or err}); do not run two sweeps into "
            "it at once",
            stacklevel=3,
        )
        return
    os.ftruncate(fd, 0)
    os.write(fd, f"{os.getpid()}\n".encode())
    _HELD[key] = fd


def _holder(fd: int) -> str:
    """The pid in a lock file; its holder writes it just after locking, so wait a little."""
    for _ in range(10):
        pid = os.pread(fd, 32, 0).decode(errors="replace").strip()
        if pid:
            return pid
        time.sleep(0.02)
    return "unknown"


def close_store(store: Path) -> None:
    """Free the lock of ``store`` taken by :func:`open_store` (or :func:`lock_store`)."""
    fd = _HELD.pop(Path(store).resolve(), None)
    if fd is not None:
        os.close(fd)  # closing the last descriptor frees the lock


def write_atomic(path: Path, text: str) -> None:
    """Write ``text`` to ``path`` through a temporary file and a rename."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    try:
        tmp.write_text(text, encoding="utf-8")
        os.replace(tmp, path)
    except OSError as err:
        # name the file the user knows (a full disk, say), not the temporary one
        raise OSError(err.errno, err.strerror, str(path)) from None
    finally:
        tmp.unlink(missing_ok=True)


def point_text(point: SweepPoint) -> str:
    """``dumps(point.to_dict())``: the point's JSON, with NaN written as null."""
    d = point.to_dict()
    try:
        # A point's dict is plain Python but for NumPy floats (floats to json) and the odd
        # NaN; the cleaning walk (a third of the time) is needed only then.
        return json.dumps(d, allow_nan=False)
    except (TypeError, ValueError):
        return dumps(d)


def store_point(store: Path, index: int, point: SweepPoint) -> str:
    """Write one finished point atomically; return its text."""
    text = point_text(point)
    write_atomic(Path(store) / "points" / f"{index:05d}.json", text)
    return text


def store_chunk(store: Path, indices: list[int], texts: list[str]) -> None:
    """Write the points of a chunk (their texts from :func:`point_text`) as one file."""
    body = f'{{"indices": {json.dumps([int(i) for i in indices])}, "points": ['
    body += ", ".join(texts) + "]}"
    write_atomic(Path(store) / "points" / f"chunk-{indices[0]:05d}-{len(indices)}.json", body)


def stored_count(store: Path) -> int:
    """How many points a store holds (without reading them)."""
    folder = Path(store) / "points"
    single = len(list(folder.glob("[0-9]*.json")))
    return single + sum(int(f.stem.rsplit("-", 1)[1]) for f in folder.glob("chunk-*-*.json"))


class _Damaged(Exception):
    """A point file that holds no valid point: why, in a few words."""


def _point(d, index: int, order: list[float]) -> SweepPoint:
    """The point of ``d`` at ``index``, checked against the sweep's ``order`` of values."""
    point = SweepPoint.from_dict(d)
    if not 0 <= index < len(order) or point.value != order[index]:
        raise ValueError("another value")
    if any(np.ndim(v) != 1 for v in point.poincare.values()):
        raise ValueError("Poincare points of another shape")
    x = point.x_final  # one value per state, as the Poincare points are
    if x is not None and (x.ndim != 1 or x.size != len(point.poincare)):
        raise ValueError("end state of another shape")
    return point


def _read_points(f: Path, order: list[float]) -> tuple[dict[int, SweepPoint], dict[int, str]]:
    """The points of one file and their texts; raises :class:`_Damaged`."""
    try:
        text = f.read_text(encoding="utf-8")
    except UnicodeDecodeError:
        raise _Damaged("not text") from None
    except OSError as err:
        raise _Damaged(f"cannot be read: {err.strerror or err}") from None
    try:
        data = json.loads(text)
    except ValueError:
        raise _Damaged("not JSON, or cut short") from None
    try:
        if f.name.startswith("chunk-"):
            first, count = (int(n) for n in f.stem.split("-")[1:])
            indices = [int(i) for i in data["indices"]]
            if len(indices) != count or indices[0] != first:
                raise ValueError("indices other than the name says")
            pairs = zip(indices, data["points"], strict=True)
            found = {i: _point(d, i, order) for i, d in pairs}
            return found, {i: point_text(p) for i, p in found.items()}
        index = int(f.stem)
        return {index: _point(data, index, order)}, {index: text}
    except (KeyError, TypeError, ValueError, AttributeError, IndexError):
        raise _Damaged("not a sweep point this version reads") from None


def _set_aside(store: Path, f: Path, why: str) -> None:
    """Move a damaged point file to ``store/damaged`` (never delete what may be evidence)."""
    folder = store / "damaged"
    folder.mkdir(exist_ok=True)
    target, k = folder / f.name, 0
    while target.exists():
        k += 1
        target = folder / f"{f.name}.{k}"
    os.replace(f, target)
    warnings.warn(
        f"{f} is damaged ({why}); moved to {target}, its points will be recomputed",
        stacklevel=4,
    )


def _old_manifest(store: Path, manifest: dict) -> dict | None:
    """The manifest stored in ``store`` (None if there is none yet), checked to be whole."""
    path = store / "manifest.json"
    if not path.exists():
        return None
    fix = f"delete {store} to start this sweep again, or choose another --out"
    try:
        old = json.loads(path.read_text(encoding="utf-8"))
    except ValueError as err:  # not UTF-8, not JSON or cut short
        why = err.msg if isinstance(err, json.JSONDecodeError) else "not text"
        raise SweepStoreError(f"{path} is damaged ({why}); {fix}") from None
    if not isinstance(old, dict):
        raise SweepStoreError(f"{path} is damaged (not a sweep manifest); {fix}")
    missing = [k for k in manifest if k not in old]
    if missing:
        raise SweepStoreError(f"{path} is damaged or incomplete (no {', '.join(missing)}); {fix}")
    return old


def open_store(
    store: Path, manifest: dict, texts: dict[int, str] | None = None
) -> dict[int, SweepPoint]:
    """Create the store, or check that it holds this very sweep; return its points (and
    put their texts into ``texts``).

    The store is locked for this process (:func:`lock_store`) until :func:`close_store`
    or the process's end.  A point file that holds no valid point is moved to
    ``store/damaged`` with a warning, and its points are left to be computed again; a
    damaged manifest, or one of another model or sweep, is refused.
    """
    store = Path(store)
    store.mkdir(parents=True, exist_ok=True)
    lock_store(store)
    old = _old_manifest(store, manifest)
    if old is None:
        write_atomic(store / "manifest.json", dumps(manifest, indent=1))
    elif old["model_hash"] != manifest["model_hash"]:
        raise SweepStoreError(
            f"{store} was written by another model version (hash "
            f"{str(old['model_hash'])[:12]}, this model {manifest['model_hash'][:12]}); "
            "choose another output folder or delete it"
        )
    elif differs := [k for k in manifest if old[k] != manifest[k]]:
        raise SweepStoreError(
            f"{store} holds another sweep ({', '.join(differs)} differ); choose another "
            "output folder or delete it"
        )
    values = [float(v) for v in manifest["values"]]
    order = values[::-1] if manifest["direction"] == "backward" else values
    done: dict[int, SweepPoint] = {}
    folder = store / "points"
    files = sorted(folder.glob("chunk-*-*.json")) + sorted(folder.glob("[0-9]*.json"))
    for f in files:
        try:
            found, found_texts = _read_points(f, order)
        except _Damaged as why:
            _set_aside(store, f, str(why))
            continue
        done.update(found)
        if texts is not None:
            texts.update(found_texts)
    return done
