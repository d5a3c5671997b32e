"""The result store of ``gearsym reproduce``: each unit of work's result kept in the model
cache, so that a repeated run with the same code and inputs loads it instead of computing
it again (issue 25, point 7).

A unit is a sweep job or one task of a batch (a run continued, an operating point, a
branch continuation, a frequency response, a sensitivity map with its figures).  Its key
is the sha256 of

* the source of gearsym (every ``.py`` file of the package: application, derive, solver,
  the generated modules) and of the built-in scenes (``*.toml``), with the versions of
  Python, NumPy, SciPy, SymPy, Matplotlib and CasADi and the C compiler's identity (as
  the compiled libraries' cache takes it): any change of code or scene makes every key
  new;
* the function that does the unit;
* every argument of the unit, walked to plain values: a model by the sha256 of its
  generated module's bytes with its parameter vector and named values, an array by its
  bytes, a path under the run's output folder by its place in it (so a run into another
  folder finds the same key), a dataclass by all its fields.

An argument the walk does not know (another object) leaves the unit unkeyed: it is always
computed.  A unit's files (figures, data written beside its result) are written into a
folder of its own under the output folder, then kept in the store with the result and
moved into place; on a hit they are written from the store.  Each entry is one file, its
payload's sha256 on the first line: an entry that does not match it is computed again.
Like the cached models (``gearsym/resolve.py``), an entry is loaded with the user's
rights (it is a pickle): the digest guards against corruption, not against someone who
can already write the user's cache.
"""

from __future__ import annotations

import copy
import dataclasses
import hashlib
import os
import pickle
import shutil
import sys
from pathlib import Path

import numpy as np

__all__ = ["KEEP", "ResultStore", "canonical", "source_hash"]

_FORMAT = 1  # of an entry; part of every key
KEEP = 3  # stores of this many sources (the newest) are kept
# whose versions can change a result (numerics, derivations, figures)
_PACKAGES = ("numpy", "scipy", "sympy", "matplotlib", "casadi")
_OUT = Path("/__gearsym_reproduce_out__")  # where the output folder stands in a kept result
_source: list[str] = []
_files: dict[str, str] = {}


def _sha256_file(path) -> str:
    path = str(path)
    if path not in _files:
        _files[path] = hashlib.sha256(Path(path).read_bytes()).hexdigest()
    return _files[path]


def source_hash() -> str:
    """sha256 of gearsym's source files (Python and the engine's C) and built-in scenes,
    with the versions of Python and of the libraries a result depends on, and the C
    compiler (once per process)."""
    if not _source:
        from importlib.metadata import PackageNotFoundError, version

        import gearsym
        from gearsym import derive, generated, solver
        from gearsym.solver.integrate.native.build import _compiler_id, compiler

        roots = [Path(p) for m in (gearsym, derive, solver, generated) for p in m.__path__]
        scenes = Path(derive.__path__[0]).parent / "scenes"
        cc = compiler()
        h = hashlib.sha256(f"{_FORMAT} {sys.version}\n{cc and _compiler_id(cc)}".encode())
        for name in _PACKAGES:
            try:
                h.update(f"{name} {version(name)}\n".encode())
            except PackageNotFoundError:
                h.update(f"{name} missing\n".encode())
        # the Python and the C of the engine (native_*.c, monodromy.c): a change to an
        # integrator's C is a change of the results as much as one to its Python
        found = {f for r in roots for pattern in ("*.py", "*.c") for f in r.rglob(pattern)}
        if scenes.is_dir():
            found |= set(scenes.rglob("*.toml"))
        for f in sorted(found):
            if "__pycache__" not in f.parts:
                h.update(f"{f.name}\0{_sha256_file(f)}\0".encode())
        _source.append(h.hexdigest())
    return _source[0]


class Unkeyed(TypeError):
    """An argument the key cannot be made of."""


_PLAIN = frozenset((float, int, str))  # exact types: repr tells their values apart


def canonical(x, out: Path):
    """``x`` as nested tuples of plain values (see the module's docstring)."""
    from gearsym.solver.system import System

    if x is None or isinstance(x, (bool, int, float, str, complex)):
        return (type(x).__name__, repr(x))
    if isinstance(x, np.generic):
        return (type(x).__name__, repr(x.item()))
    if isinstance(x, Path):
        try:
            return ("out", str(x.relative_to(out)))
        except ValueError:
            return ("path", str(x))
    if isinstance(x, System):
        where = x.module.__file__
        return ("System", _sha256_file(where), canonical(x.p, out), canonical(x.values, out))
    if isinstance(x, np.ndarray):
        if x.dtype == object:
            return ("objects", x.shape, tuple(canonical(v, out) for v in x.ravel()))
        data = hashlib.sha256(np.ascontiguousarray(x).tobytes()).hexdigest()
        return ("array", str(x.dtype), x.shape, data)
    if isinstance(x, (list, tuple)):
        kinds = set(map(type, x))
        if len(kinds) == 1 and kinds <= _PLAIN:  # a row of numbers or texts in one go
            return (type(x).__name__, next(iter(kinds)).__name__, repr(tuple(x)))
        return (type(x).__name__, tuple(canonical(v, out) for v in x))
    if isinstance(x, dict):
        items = [(canonical(k, out), canonical(v, out)) for k, v in x.items()]
        # ordered by the keys alone: distinct keys have distinct canonical forms, and the
        # repr of every value's whole subtree at every level of a nested record made the
        # keys of a reproduce's tasks cost seconds of the main process's time
        return ("dict", tuple(sorted(items, key=_first_repr)))
    if isinstance(x, (set, frozenset)):
        return ("set", tuple(sorted((canonical(v, out) for v in x), key=repr)))
    if dataclasses.is_dataclass(x) and not isinstance(x, type):
        fields = tuple((f.name, canonical(getattr(x, f.name), out)) for f in dataclasses.fields(x))
        return (type(x).__module__, type(x).__qualname__, fields)
    if callable(x) and hasattr(x, "__qualname__"):
        return ("function", x.__module__, x.__qualname__)
    raise Unkeyed(type(x).__qualname__)


def _first_repr(pair: tuple) -> str:
    return repr(pair[0])


def _moved(x, old: Path, new: Path):
    """``x`` with every path under ``old`` moved under ``new`` (copies where one is)."""
    if isinstance(x, Path):
        try:
            return new / x.relative_to(old)
        except ValueError:
            return x
    if isinstance(x, (list, tuple)):
        items = [_moved(v, old, new) for v in x]
        same = all(a is b for a, b in zip(items, x, strict=True))
        return x if same else type(x)(items)
    if isinstance(x, dict):
        items = {k: _moved(v, old, new) for k, v in x.items()}
        return x if all(items[k] is x[k] for k in x) else items
    if dataclasses.is_dataclass(x) and not isinstance(x, type):
        changed = {}
        for f in dataclasses.fields(x):
            v = getattr(x, f.name)
            w = _moved(v, old, new)
            if w is not v:
                changed[f.name] = w
        if not changed:
            return x
        y = copy.copy(x)
        for name, w in changed.items():
            object.__setattr__(y, name, w)
        return y
    return x


class _Unit:
    """Worker: one unit run with the output folder replaced by a folder of its own;
    its result (the output folder as :data:`_OUT`) and the files it wrote."""

    def __init__(self, fn, out: Path):
        self.fn, self.out = fn, Path(out)

    def __call__(self, item):
        key, task = item
        if key is None:
            return self.fn(task), None
        # named by the key: a unit stopped half-way (Ctrl-C) resumes its stores from here
        scratch = self.out / ".units" / key[:24]
        for sub in self.out.iterdir():  # the folders a unit may expect (data/, ...)
            if sub.is_dir() and sub.name not in (".units", "store"):
                (scratch / sub.name).mkdir(parents=True, exist_ok=True)
        scratch.mkdir(parents=True, exist_ok=True)
        result = _moved(self.fn(_moved(task, self.out, scratch)), scratch, _OUT)
        files = {
            str(p.relative_to(scratch)): p.read_bytes()
            for p in sorted(scratch.rglob("*"))
            if p.is_file() and p.name != "lock"
        }
        shutil.rmtree(scratch)
        return result, files


class ResultStore:
    """The entries of one run: ``root`` (``<cache>/results``), ``fresh`` (compute every
    unit, keep the results), the output folder; counts of units loaded and computed."""

    def __init__(self, root: Path, out: Path, *, fresh: bool = False):
        self.root, self.out, self.fresh = Path(root), Path(out), fresh
        self.loaded = self.computed = 0

    @classmethod
    def in_cache(cls, out: Path, *, fresh: bool = False) -> ResultStore:
        """The store of this source in ``<cache>/results/<source hash>``; the stores of
        older sources beyond the :data:`KEEP` newest are removed (a full run keeps about
        35 MB, most of it figures)."""
        from gearsym.solver.cache import cache_root

        root = cache_root() / "results"
        here = root / source_hash()[:16]
        here.mkdir(parents=True, exist_ok=True)
        os.utime(here)
        older = sorted(
            (d for d in root.iterdir() if d.is_dir() and d != here),
            key=lambda d: d.stat().st_mtime,
            reverse=True,
        )
        for old in older[KEEP - 1 :]:
            shutil.rmtree(old, ignore_errors=True)
        return cls(here, out, fresh=fresh)

    def key(self, fn, task) -> str | None:
        try:
            made = canonical((fn, task), self.out)
        except Unkeyed:
            return None
        return hashlib.sha256(f"{source_hash()}\n{made!r}".encode()).hexdigest()

    def _path(self, key: str) -> Path:
        return self.root / key[:2] / f"{key}.pickle"

    def has(self, key: str | None) -> bool:
        """Whether an entry of ``key`` is there to load (not checked yet)."""
        return key is not None and not self.fresh and self._path(key).is_file()

    def load(self, key: str | None):
        """``(result, files)`` of ``key``, or None (not kept, damaged, or ``fresh``)."""
        if key is None or self.fresh:
            return None
        try:
            digest, payload = self._path(key).read_bytes().split(b"\n", 1)
        except (OSError, ValueError):
            return None
        if hashlib.sha256(payload).hexdigest().encode() != digest:
            return None
        try:
            return pickle.loads(payload)
        except Exception:  # an entry of other code that slipped past the key: compute
            return None

    def keep(self, key: str | None, entry) -> None:
        if key is None:
            return
        payload = pickle.dumps(entry, protocol=pickle.HIGHEST_PROTOCOL)
        path = self._path(key)
        path.parent.mkdir(parents=True, exist_ok=True)
        tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
        tmp.write_bytes(hashlib.sha256(payload).hexdigest().encode() + b"\n" + payload)
        os.replace(tmp, path)

    def place(self, entry):
        """Write a unit's files into the output folder; its result there."""
        result, files = entry
        for name, data in (files or {}).items():
            path = self.out / name
            path.parent.mkdir(parents=True, exist_ok=True)
            path.write_bytes(data)
        return _moved(result, _OUT, self.out)

    def kept(self, keys: list, on_hit=None) -> tuple[list, list]:
        """(results, indices to compute) of ``keys``: each kept unit placed (its files
        written), ``on_hit(index, result)`` called for it; None where it is to compute."""
        out: list = [None] * len(keys)
        todo = []
        for k, key in enumerate(keys):
            entry = self.load(key)
            if entry is None:
                todo.append(k)
                continue
            out[k] = self.place(entry)
            self.loaded += 1
            if on_hit is not None:
                on_hit(k, out[k])
        return out, todo

    def map(self, fn, tasks, *, executor: str, workers, on_result=None) -> list:
        """``[fn(t) for t in tasks]`` as :func:`~gearsym.solver.sweep.map_tasks` does,
        each unit loaded from the store where it is kept there."""
        from gearsym.solver.sweep import map_tasks

        tasks = list(tasks)
        keys = [self.key(fn, t) for t in tasks]
        out, todo = self.kept(keys, None if on_result is None else lambda k, r: on_result(r))
        if not todo:
            return out
        place = iter(todo)

        def arrived(entry) -> None:
            k = next(place)
            self.keep(keys[k], entry)
            out[k] = self.place(entry)
            self.computed += 1
            if on_result is not None:
                on_result(out[k])

        items = [(keys[k], tasks[k]) for k in todo]
        map_tasks(_Unit(fn, self.out), items, executor=executor, workers=workers, on_result=arrived)
        try:
            (self.out / ".units").rmdir()  # empty once every unit is done
        except OSError:
            pass
        return out

    def summary(self) -> str:
        """``'40 of 64 units of work loaded from the result store, 24 computed'``."""
        total = self.loaded + self.computed
        if self.fresh:
            return f"all {total} units of work computed (--fresh)"
        return (
            f"{self.loaded} of {total} units of work loaded from the result store, "
            f"{self.computed} computed"
        )
