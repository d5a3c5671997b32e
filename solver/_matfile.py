"""A MATLAB level-5 ``.mat`` writer for the nested results of :mod:`.export`.

gearsym wrote its ``.mat`` files with ``scipy.io.savemat``, which writes nested data one
element at a time through Python objects, about 16 µs an element: a 400-point sweep of a
34-state model (455,000 elements: every point's per-state evidence, spectra and
Poincaré points) took 7 s to write, more than its JSON and CSV together.  This writer
builds the file by joining bytes: the classes, shapes, field names and values that
``savemat(..., long_field_names=True, do_compression=True)`` wrote of the same result
(dicts as structs, lists of numbers as arrays, other lists as cell arrays, null as NaN,
booleans as double), which ``scipy.io.loadmat`` reads back identically
(``tests/solver/test_matfile.py`` compares the two, savemat fed by the old conversion).

The layout is the MathWorks "MAT-File Format" (level 5): a 128-byte header, then one
data element per variable, each compressed (``miCOMPRESSED``, zlib) around an
``miMATRIX`` element: array flags, dimensions, name, then the class's data --

* double or int64 arrays (column-major; a 1-D array a 1 x n row, a scalar 1 x 1, an
  empty one 0 x 0);
* text as a 1 x n char array in UTF-8 (``miUTF8``; "" as a 0 x 0 char array);
* a list that is not all numbers as a cell array (1 x n), each element a nameless matrix;
* a dict as a 1 x 1 struct: the longest field name's length plus one, the names
  NUL-padded to it, then each field's value as a nameless matrix (no fields: an empty
  struct, as savemat writes ``{}``).
"""

from __future__ import annotations

import functools
import math
import struct
import time
import zlib

import numpy as np

from ._json import clean

__all__ = ["mat_bytes"]

_INT8, _INT32, _UINT32, _DOUBLE, _INT64 = 1, 5, 6, 9, 12
_MATRIX, _COMPRESSED, _UTF8 = 14, 15, 16
_CELL, _STRUCT, _CHAR, _DOUBLE_CLASS, _INT64_CLASS = 1, 2, 4, 6, 14
_PAD = (b"", b"\0" * 7, b"\0" * 6, b"\0" * 5, b"\0" * 4, b"\0" * 3, b"\0" * 2, b"\0")


def _element(kind: int, data: bytes) -> bytes:
    """A data element: the small format (tag and data in 8 bytes) up to 4 bytes of data,
    else an 8-byte tag and the data padded to a multiple of 8 bytes."""
    n = len(data)
    if 0 < n <= 4:
        return struct.pack("<HH", kind, n) + data + b"\0" * (4 - n)
    return struct.pack("<II", kind, n) + data + _PAD[n % 8]


def _matrix(cls: int, dims, name: bytes, body: list) -> list:
    """An miMATRIX element in parts: its tag, array flags, dimensions, name and ``body``
    (parts already padded)."""
    head = _head(cls, tuple(dims), name)
    return [struct.pack("<II", _MATRIX, len(head) + sum(map(len, body))), head, *body]


@functools.lru_cache(maxsize=4096)
def _head(cls: int, dims: tuple, name: bytes) -> bytes:
    """An miMATRIX element's array flags, dimensions and name (a result repeats a few of
    them many times: a nameless 1 x 1 struct per point, state and peak)."""
    return b"".join(
        (
            _element(_UINT32, struct.pack("<II", cls, 0)),
            _element(_INT32, struct.pack(f"<{len(dims)}i", *dims)),
            _element(_INT8, name),
        )
    )


def _dims(shape: tuple) -> tuple:
    """MATLAB's dimensions of a NumPy shape, as savemat gives them (1-D as a row)."""
    if len(shape) == 0:
        return (1, 1)
    if len(shape) == 1:
        return (1, shape[0]) if shape[0] else (0, 0)
    return shape


def _numeric(a: np.ndarray, name: bytes) -> list:
    if a.dtype.kind in "iu" and a.dtype != np.float64:
        cls, kind, a = _INT64_CLASS, _INT64, a.astype("<i8")
    else:
        cls, kind, a = _DOUBLE_CLASS, _DOUBLE, a.astype("<f8", copy=False)
    data = a.tobytes(order="F") if a.ndim > 1 else a.tobytes()
    return _matrix(cls, _dims(a.shape), name, [_element(kind, data)])


def _text(s: str, name: bytes) -> list:
    if not s:
        return _matrix(_CHAR, (0, 0), name, [_element(_UTF8, b"")])
    return _matrix(_CHAR, (1, len(s)), name, [_element(_UTF8, s.encode("utf-8"))])


# a nameless 1 x 1 double or int64 (the commonest elements of a result) up to their 8
# bytes of data
def _scalar(cls: int, kind: int) -> bytes:
    whole = b"".join(_matrix(cls, (1, 1), b"", [struct.pack("<II", kind, 8)]))
    return struct.pack("<II", _MATRIX, len(whole)) + whole[8:]


_SCALAR, _INT_SCALAR = _scalar(_DOUBLE_CLASS, _DOUBLE), _scalar(_INT64_CLASS, _INT64)


_NUMBERS = frozenset((float, int, bool, type(None)))  # a number in JSON form, or null


def _numbers(items: list) -> bool:
    """Whether every item of a list in JSON form is a number or null (by exact type: the
    form holds no subclasses)."""
    return set(map(type, items)) <= _NUMBERS


def _floats(items: list) -> np.ndarray:
    """A list of numbers and nulls as doubles, null and infinities as NaN (as their JSON
    form, null, would be)."""
    if None in items:
        a = np.array([np.nan if v is None else v for v in items], dtype=float)
    else:
        a = np.array(items, dtype=float)
    if not np.isfinite(a).all():
        a[~np.isfinite(a)] = np.nan
    return a


def _parts(obj, name: bytes = b"") -> list:
    """``obj`` (a result's ``to_dict()`` or a table) as an miMATRIX element in parts, by
    ``export``'s rules: dicts as structs (field names cleaned), float arrays as they are,
    everything else as its JSON form (``clean``: NaN and infinities as null) with lists
    of numbers as arrays (rectangular lists of them as matrices), other lists as cell
    arrays, null as NaN and booleans as double."""
    if isinstance(obj, np.ndarray) and obj.dtype.kind in "fiub":
        return _numeric(np.asarray(obj, dtype=float), name)
    if isinstance(obj, dict):
        return _struct(obj, name, _parts)
    return _json(obj, name)


# exact types whose values are their own JSON form (a non-finite float aside, which
# _clean writes as NaN, as it writes the null that is its JSON form)
_PLAIN = frozenset((float, int, bool, str, type(None)))
_RECORDS = _PLAIN | {dict}


def _json(obj, name: bytes = b"") -> list:
    """``_clean(clean(obj), name)`` in one walk: records (dicts, lists of them and of
    plain values) are not converted to their JSON form first and walked again, which took
    half the time of a 400-point sweep's file; anything else (NumPy values, arrays and
    nested lists inside them) is converted as ``clean`` converts it."""
    kind = type(obj)
    if kind in _PLAIN:
        return _clean(obj, name)
    if kind is dict:
        return _struct({str(k): v for k, v in obj.items()}, name, _json)
    if kind is list or kind is tuple:
        kinds = set(map(type, obj))
        if kinds <= _PLAIN:
            return _clean(list(obj), name)
        if dict in kinds and kinds <= _RECORDS:  # no number nor matrix: a cell array
            return _matrix(_CELL, (1, len(obj)), name, [p for v in obj for p in _json(v)])
    return _clean(clean(obj), name)


def _base(obj):
    """A subclass's value as its base type (an enum's value), as the JSON form keeps
    them and :func:`_clean` writes them."""
    if isinstance(obj, float):
        return float(obj)
    if isinstance(obj, str):
        return "" + obj
    if isinstance(obj, int):
        return int(obj)
    if isinstance(obj, dict):
        return dict(obj)
    return list(obj)


_EXACT = _PLAIN | {dict, list}


def _clean(obj, name: bytes = b"") -> list:
    """:func:`_parts` of data already in its JSON form."""
    kind = type(obj)
    if kind not in _EXACT:
        obj = _base(obj)
        kind = type(obj)
    if kind is float or obj is None:
        value = obj if obj is not None and math.isfinite(obj) else np.nan
        if not name:
            return [_SCALAR + struct.pack("<d", value)]
        return _numeric(np.array(value), name)
    if kind is str:
        return _text(obj, name)
    if kind is bool:
        return _clean(float(obj), name)
    if kind is int:
        if -(2**63) <= obj < 2**63:
            if not name:
                return [_INT_SCALAR + struct.pack("<q", obj)]
            return _numeric(np.array(obj, dtype=np.int64), name)
        return _numeric(np.array(float(obj)), name)  # past int64: a double
    if kind is dict:
        return _struct(obj, name, _clean)
    if obj and _numbers(obj):
        return _numeric(_floats(obj), name)
    if (
        obj
        and all(isinstance(r, list) and r and _numbers(r) for r in obj)
        and len({len(r) for r in obj}) == 1
    ):
        return _numeric(np.array([_floats(r) for r in obj], dtype=float), name)
    body = [p for v in obj for p in _clean(v)]
    return _matrix(_CELL, (1, len(obj)) if obj else (0, 0), name, body)


def _struct(fields: dict, name: bytes, each) -> list:
    """A 1 x 1 struct of ``fields`` (names cleaned as ``export`` cleans them), each value
    written by ``each``."""
    # as text: the caches below would take 1, 1.0 and True for one key
    keys = tuple(map(str, fields))
    if _collide(keys):  # two keys one field name: the later value, as a dict keeps it
        fields = {_field(k): v for k, v in fields.items()}
        keys = tuple(fields)
    body = [_names(keys)]
    for v in fields.values():
        body.extend(each(v))
    return _matrix(_STRUCT, (1, 1), name, body)


@functools.lru_cache(maxsize=4096)
def _collide(keys: tuple) -> bool:
    """Whether two of ``keys`` clean to one field name (``a-b`` and ``a_b``)."""
    return len({_field(k) for k in keys}) < len(keys)


@functools.lru_cache(maxsize=4096)
def _names(keys: tuple) -> bytes:
    """A struct's field-name length and names (a result repeats a few sets of keys many
    times: once per point, state and peak); no keys: savemat's empty struct."""
    if not keys:
        return _element(_INT32, struct.pack("<i", 1)) + _element(_INT8, b"")
    names = [_field(k).encode("ascii") for k in keys]
    width = max(map(len, names)) + 1
    return _element(_INT32, struct.pack("<i", width)) + _element(
        _INT8, b"".join(n + b"\0" * (width - len(n)) for n in names)
    )


def _field(name) -> str:
    """A MATLAB field name: letters, digits and underscores, starting with a letter."""
    s = "".join(ch if ch.isalnum() else "_" for ch in str(name))
    return s if s[:1].isalpha() else f"x_{s}"


def mat_bytes(variables: dict, level: int = 1) -> bytes:
    """The whole ``.mat`` file of ``variables`` (name -> a result's ``to_dict()`` or a
    table), each variable compressed with zlib at ``level``: 1, not savemat's 6, which
    took 0.8 s more on a 400-point sweep's 44 MB for a file 5 % smaller (8.2 MB)."""
    # asctime, as savemat: English names whatever the locale
    text = f"MATLAB 5.0 MAT-file Platform: posix, Created on: {time.asctime()} by gearsym"
    text = text.encode("ascii")
    out = [text[:116].ljust(116, b" "), b"\0" * 8, struct.pack("<H", 0x0100), b"IM"]
    for name, value in variables.items():
        raw = zlib.compress(b"".join(_parts(value, name.encode("ascii"))), level)
        out.append(struct.pack("<II", _COMPRESSED, len(raw)) + raw)
    return b"".join(out)
