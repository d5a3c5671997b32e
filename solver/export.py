"""Results to files other tools open: JSON, CSV and MATLAB ``.mat``.

Every result type has ``to_dict()`` (all of it, nested, under the API's attribute names)
and ``to_table()`` (the part that is a table: one row per sample, sweep point or branch
point).  :func:`save` writes

* ``.json`` -- ``to_dict()``, with NaN and infinities as ``null``;
* ``.csv`` -- the header block (:mod:`.provenance`) as leading ``# key: value`` lines, the
  value in JSON, then ``to_table()`` with one line of column names; booleans as 1/0,
  missing numbers empty (``pandas.read_csv(f, comment="#")``, MATLAB
  ``readtable(f, "CommentStyle", "#")``);
* ``.mat`` -- ``to_dict()`` as the struct ``result`` (MATLAB level 5, compressed: the
  file ``scipy.io.savemat`` writes, by :mod:`._matfile`; text as cell arrays of strings,
  booleans as double 0/1, null as NaN, rectangular lists of numbers as matrices), with
  the table's columns beside it in the struct ``table``;

each through a temporary file and a rename, so that a reader never sees half a file.
"""

from __future__ import annotations

import csv
import io
import os
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ._json import clean, dumps
from ._matfile import _field, mat_bytes
from .provenance import KEYS

__all__ = ["FORMATS", "Document", "document", "save", "save_all", "save_csv"]

FORMATS = (".json", ".csv", ".mat")


@dataclass(frozen=True)
class Document:
    """A result assembled by a command (a dict and its table) that :func:`save` writes
    like any result type."""

    data: dict
    columns: list = field(default_factory=list)
    rows: list = field(default_factory=list)

    def to_dict(self) -> dict:
        return self.data

    def to_table(self) -> tuple[list, list]:
        return self.columns, self.rows


def document(result, **extra) -> dict:
    """``result.to_dict()`` with ``extra`` (header keys such as ``initial_state`` and
    ``command``; the result's own keys win) and the header keys first."""
    data = {**extra, **result.to_dict()}
    return {k: data[k] for k in KEYS if k in data} | data


def save(result, path, **extra) -> Path:
    """Write ``result`` to ``path``; the format follows the suffix (:data:`FORMATS`).
    ``extra`` adds header keys (:func:`document`).  Arrays (a long run's samples) are
    written in blocks, never as one list or one text in memory."""
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix not in FORMATS:
        raise ValueError(f"{path}: unknown format '{suffix}'; formats: {', '.join(FORMATS)}")
    data = document(result, **extra)
    if suffix == ".json":
        return write_atomic(path, _json_parts(data))
    if suffix == ".csv":
        return write_atomic(path, _csv(data, *result.to_table()))
    columns, rows = result.to_table()
    if isinstance(rows, np.ndarray):
        table = {_field(c): np.asarray(rows[:, k], dtype=float) for k, c in enumerate(columns)}
    else:
        table = {_field(c): _column([r[k] for r in rows]) for k, c in enumerate(columns)}
    # the file scipy.io.savemat(..., long_field_names=True, do_compression=True) writes
    # of the same content, built six to ten times as fast (_matfile.py)
    return write_atomic(path, mat_bytes({"result": data, "table": table}))


def save_all(result, path, **extra) -> list[Path]:
    """``result`` in every format (:data:`FORMATS`) beside ``path``, whose suffix is
    replaced: ``sweep.json`` -> ``sweep.json``, ``sweep.csv``, ``sweep.mat``."""
    path = Path(path)
    write = getattr(result, "save", None) or (lambda p, **kw: save(result, p, **kw))
    return [write(path.with_suffix(suffix), **extra) for suffix in FORMATS]


def save_csv(path, data: dict, columns, rows) -> Path:
    """A table as a CSV file, opened by ``data``'s header block as :func:`save` writes it
    (a second table of a result, such as a sweep's Poincare points)."""
    return write_atomic(path, _csv(data, columns, rows))


def write_atomic(path, content) -> Path:
    """Write ``content`` to ``path`` through a temporary file and a rename: text, bytes,
    an iterable of text or bytes parts, or a function that writes to a binary file."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    parts = [content] if isinstance(content, str | bytes) else content
    try:
        with open(tmp, "wb") as fh:
            if callable(parts):
                parts(fh)
            for part in () if callable(parts) else parts:
                fh.write(part if isinstance(part, bytes) else part.encode("utf-8"))
        os.replace(tmp, path)
    finally:
        tmp.unlink(missing_ok=True)
    return path


_BLOCK = 8192  # array entries (or table rows) per written block


def _json_parts(obj):
    """``dumps(obj)`` in parts: the same text, with long float arrays written block by
    block (``json.dumps`` separators: ``", "`` and ``": "``)."""
    if isinstance(obj, dict):
        yield "{"
        for k, (key, value) in enumerate(obj.items()):
            yield (", " if k else "") + dumps(str(key)) + ": "
            yield from _json_parts(value)
        yield "}"
    elif isinstance(obj, np.ndarray) and obj.ndim == 1 and obj.size > _BLOCK:
        yield "["
        for k in range(0, obj.size, _BLOCK):
            yield (", " if k else "") + dumps(obj[k : k + _BLOCK])[1:-1]
        yield "]"
    else:
        yield dumps(obj)


def _csv(data: dict, columns, rows):
    """The CSV text in parts: the header lines, the column names, then the rows in
    blocks (an array of rows: non-finite entries as empty cells)."""
    head = io.StringIO()
    for k in KEYS:
        if k in data:
            head.write(f"# {k}: {dumps(data[k])}\n")
    csv.writer(head, lineterminator="\n").writerow(columns)
    yield head.getvalue()
    for k in range(0, len(rows), _BLOCK):
        out = io.StringIO()
        writer = csv.writer(out, lineterminator="\n")
        block = rows[k : k + _BLOCK]
        if not isinstance(block, np.ndarray):  # each row read twice below: no iterators
            block = [r if isinstance(r, list | tuple) else list(r) for r in block]
        if isinstance(block, np.ndarray):
            writer.writerows(clean(np.asarray(block, dtype=float)))
        elif _plain(block):
            yield "".join(",".join(map(repr, row)) + "\n" for row in block)
            continue
        else:
            writer.writerows([_cell(v) for v in row] for row in block)
        yield out.getvalue()


_NUMBERS = frozenset((float, int))


def _plain(block) -> bool:
    """Whether every cell of ``block`` (a list of rows) is a finite float or an int (not a
    bool): then ``repr`` joined by commas is what ``csv.writer`` writes, in about half the
    time (a 400-point sweep's Poincare table: 1.4 million cells)."""
    cells = [v for row in block for v in row]
    if not set(map(type, cells)) <= _NUMBERS:
        return False
    floats = [v for v in cells if type(v) is float]
    return bool(np.isfinite(np.asarray(floats, dtype=float)).all()) if floats else True


def _cell(v):
    v = clean(v)
    if v is None:
        return ""
    if isinstance(v, bool):
        return int(v)
    return v


def _column(values: list):
    """A table column: text as a cell array of strings, else double (None as NaN)."""
    values = [clean(v) for v in values]
    if any(isinstance(v, str) for v in values):
        return _cells(["" if v is None else str(v) for v in values])
    return np.array([np.nan if v is None else float(v) for v in values], dtype=float)


def _cells(items: list) -> np.ndarray:
    """An object array (a MATLAB cell array) of ``items``, never a char matrix."""
    out = np.empty(len(items), dtype=object)
    out[:] = items
    return out
