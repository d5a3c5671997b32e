"""The one store of classified runs, for sweeps and regime maps: a folder with its
metadata and the finished runs, every file written atomically (temporary file, then
rename), so that nothing computed is lost and a torn file cannot exist.

:class:`RunStore` is the whole interface: :meth:`RunStore.open` creates the folder or
checks that it holds this very work (metadata: kind, model hash, parameter values,
settings), :meth:`~RunStore.append` writes finished runs under integer keys,
:meth:`~RunStore.read` gives them back, :meth:`~RunStore.done` says which keys are done
(resume), :meth:`~RunStore.count` how many runs it holds without reading them.  What
the files inside are called is this module's business alone.

Runs that finish together (a lockstep chunk, a map's column) are one file, not one each:
creating 400 small files took 0.2 s of a 400-point sweep's CPU time.  One process writes
into a store at a time (a lock the kernel frees when the process ends, however it ends;
its workers append under the parent's lock).  A file that holds no valid run is moved to
``damaged/`` and its runs computed again; damaged metadata is refused, as is that of
other work.  A store of gearsym's first format (before one format served sweeps and
maps) is refused in one line: delete it and the work is computed again.
"""

from __future__ import annotations

import json
import os
import time
import warnings
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .._json import dumps
from ..analysis.record import RunRecord

__all__ = [
    "STORE_FORMAT",
    "RunStore",
    "SweepStoreError",
    "record_text",
    "stored_count",
    "write_atomic",
]

STORE_FORMAT = 3  # 3: one verdict per attractor, with its evidence (issue 27)
_MANIFEST = "manifest.json"
_RUNS = "points"  # the runs' files: <first key>-<count>.json


class SweepStoreError(ValueError):
    """A store that cannot be written or resumed: another model, other work, damaged
    metadata, a store of an older format, or another process writing into it."""


try:
    import fcntl
except ImportError:  # not POSIX: stores are not locked
    fcntl = None

_HELD: dict[Path, int] = {}  # store folder -> descriptor of its lock, held by this process


def _lock(store: Path) -> None:
    """Lock ``store`` for this process, or refuse at once if another process holds it.

    The lock (``flock`` on ``store/lock``, which holds the holder's pid) lasts until
    :meth:`RunStore.close` or the end of the process, however it ends: the kernel frees it
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


def _unlock(store: Path) -> None:
    """Free the lock of ``store`` taken by :func:`_lock`."""
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


def record_text(record: RunRecord) -> str:
    """``dumps(record.to_dict())``: the run's JSON, with NaN written as null."""
    d = record.to_dict()
    try:
        # A record's dict is plain Python but for NumPy floats (floats to json) and the odd
        # NaN; the cleaning walk (a third of the time) is needed only then.
        return json.dumps(d, allow_nan=False)
    except (TypeError, ValueError):
        return dumps(d)


def stored_count(root: Path) -> int:
    """How many runs the store at ``root`` holds, without reading them (0: none yet)."""
    folder = Path(root) / _RUNS
    return sum(int(f.stem.rsplit("-", 1)[1]) for f in folder.glob("[0-9]*-[0-9]*.json"))


class _Damaged(Exception):
    """A file that holds no valid run: why, in a few words."""


def _checked(record: RunRecord) -> RunRecord:
    """A record read back, its arrays checked to be one value per state."""
    if any(np.ndim(v) != 1 for v in record.poincare.values()):
        raise ValueError("Poincare points of another shape")
    for x in (record.x_final, record.x0):  # one value per state, as the Poincare points
        if x is not None and (x.ndim != 1 or x.size != len(record.poincare)):
            raise ValueError("a state of another shape")
    return record


def _read_file(f: Path, check) -> dict[int, RunRecord]:
    """The runs of one file by key; raises :class:`_Damaged`."""
    try:
        data = json.loads(f.read_text(encoding="utf-8"))
    except UnicodeDecodeError:
        raise _Damaged("not text") from None
    except OSError as err:
        raise _Damaged(f"cannot be read: {err.strerror or err}") from None
    except ValueError:
        raise _Damaged("not JSON, or cut short") from None
    try:
        first, count = (int(n) for n in f.stem.split("-"))
        keys = [int(k) for k in data["keys"]]
        if len(keys) != count or keys[0] != first:
            raise ValueError("keys other than the name says")
        found = {}
        for key, d in zip(keys, data["runs"], strict=True):
            record = _checked(RunRecord.from_dict(d))
            if check is not None:
                check(key, record)
            found[key] = record
        return found
    except (KeyError, TypeError, ValueError, AttributeError, IndexError):
        raise _Damaged("not a run this version reads") from None


def _set_aside(root: Path, f: Path, why: str) -> None:
    """Move a damaged file to ``root/damaged`` (never delete what may be evidence)."""
    folder = root / "damaged"
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


def _stored_metadata(root: Path, metadata: dict) -> dict | None:
    """The metadata stored in ``root`` (None if there is none yet), checked to be whole
    and of this format."""
    path = root / _MANIFEST
    if not path.exists():
        return None
    fix = f"delete {root} to start this work again, or choose another --out"
    try:
        old = json.loads(path.read_text(encoding="utf-8"))
    except ValueError as err:  # not UTF-8, not JSON or cut short
        why = err.msg if isinstance(err, json.JSONDecodeError) else "not text"
        raise SweepStoreError(f"{path} is damaged ({why}); {fix}") from None
    if not isinstance(old, dict):
        raise SweepStoreError(f"{path} is damaged (not a store's metadata); {fix}")
    if "format" in old or "kind" in old:
        if old.get("format") != STORE_FORMAT:
            raise SweepStoreError(
                f"{root} was written by an older gearsym (store format "
                f"{old.get('format', 1)}, this one reads {STORE_FORMAT}); {fix}"
            )
    missing = [k for k in metadata if k not in old]
    if missing:
        raise SweepStoreError(f"{path} is damaged or incomplete (no {', '.join(missing)}); {fix}")
    return old


@dataclass(frozen=True)
class RunStore:
    """A folder of classified runs (:class:`RunRecord`) under integer keys, with the
    metadata of the work they belong to.  Picklable: a worker process appends to the
    store its parent opened (and locked)."""

    root: Path
    metadata: dict

    @classmethod
    def open(cls, root: Path, *, kind: str, model_hash, values: dict, **more) -> RunStore:
        """Create the store at ``root``, or check that it holds this very work.

        ``kind`` names the work (``sweep``, ``map``); ``model_hash`` the model (a list
        of hashes when the work spans several); ``values`` the varied parameters' values,
        ``{name: [value, ...]}``; ``more`` whatever else makes the work (the values every
        run shares, the settings).  The store is locked for this process until :meth:`close` or the
        process's end.  Refused (:class:`SweepStoreError`, one line): damaged metadata,
        a store of another model version, of other work or of an older format, or one
        another process is writing into.
        """
        root = Path(root)
        metadata = json.loads(
            dumps(
                {
                    "format": STORE_FORMAT,
                    "kind": kind,
                    "model_hash": model_hash,
                    "values": values,
                    **more,
                }
            )
        )  # as stored: NumPy numbers and tuples made JSON
        root.mkdir(parents=True, exist_ok=True)
        _lock(root)
        try:
            old = _stored_metadata(root, metadata)
            if old is None:
                write_atomic(root / _MANIFEST, dumps(metadata, indent=1))
            elif old["kind"] != kind:
                raise SweepStoreError(
                    f"{root} holds a {old['kind']}, not a {kind}; choose another output "
                    "folder or delete it"
                )
            elif old["model_hash"] != metadata["model_hash"]:
                was, now = (str(h)[:12] for h in (old["model_hash"], metadata["model_hash"]))
                raise SweepStoreError(
                    f"{root} was written by another model version (hash {was}, this model "
                    f"{now}); choose another output folder or delete it"
                )
            elif differs := [k for k in metadata if old[k] != metadata[k]]:
                raise SweepStoreError(
                    f"{root} holds another {kind} ({', '.join(differs)} differ); choose "
                    "another output folder or delete it"
                )
        except BaseException:
            _unlock(root)
            raise
        return cls(root, metadata)

    def append(self, records: dict[int, RunRecord], texts: dict[int, str] | None = None):
        """Write finished runs as one file, atomically; return their JSON texts (those
        in ``texts`` are taken as the records' :func:`record_text`)."""
        texts = texts or {}
        out = {int(k): texts.get(k) or record_text(r) for k, r in records.items()}
        keys = list(out)
        if not keys:
            return {}
        body = f'{{"keys": {json.dumps(keys)}, "runs": [' + ", ".join(out.values()) + "]}"
        write_atomic(self.root / _RUNS / f"{keys[0]:05d}-{len(keys)}.json", body)
        return out

    def read(self, check=None, texts: dict[int, str] | None = None) -> dict[int, RunRecord]:
        """The stored runs by key (and their texts into ``texts``).  ``check(key,
        record)`` may raise ValueError for a run that is not this work's; a file with
        such a run, or none valid, is moved to ``damaged/`` with a warning."""
        done: dict[int, RunRecord] = {}
        for f in sorted((self.root / _RUNS).glob("[0-9]*-[0-9]*.json")):
            try:
                found = _read_file(f, check)
            except _Damaged as why:
                _set_aside(self.root, f, str(why))
                continue
            done.update(found)
            if texts is not None:
                texts.update({k: record_text(r) for k, r in found.items()})
        return done

    def done(self) -> set[int]:
        """The keys of the runs the store holds (what a resumed run need not compute)."""
        return set(self.read())

    def count(self) -> int:
        """How many runs the store holds, without reading them."""
        return stored_count(self.root)

    def close(self) -> None:
        """Free the lock, for the next writer."""
        _unlock(self.root)
