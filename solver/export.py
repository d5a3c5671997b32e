"""Results to files other tools open: JSON, CSV and MATLAB ``.mat``.

Every result type has ``to_dict()`` (all of it, nested) and ``to_table()`` (the part that
is a table: one row per sample, sweep point or branch point).  :func:`save` writes

* ``.json`` -- ``to_dict()``, with NaN and infinities as ``null``;
* ``.csv`` -- ``to_table()``, one header line of column names;
* ``.mat`` -- ``to_dict()`` as MATLAB structs (``scipy.io.savemat``), with the table's
  columns beside it under ``table`` so that a MATLAB user gets plain vectors;

each through a temporary file and a rename, so that a reader never sees half a file.
"""

from __future__ import annotations

import csv
import io
import math
import os
from pathlib import Path

import numpy as np

from ._json import clean, dumps

__all__ = ["FORMATS", "save"]

FORMATS = (".json", ".csv", ".mat")


def save(result, path) -> Path:
    """Write ``result`` to ``path``; the format follows the suffix (:data:`FORMATS`)."""
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix not in FORMATS:
        raise ValueError(f"{path}: unknown format '{suffix}'; formats: {', '.join(FORMATS)}")
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    try:
        if suffix == ".json":
            tmp.write_text(dumps(result.to_dict()), encoding="utf-8")
        elif suffix == ".csv":
            tmp.write_text(_csv(*result.to_table()), encoding="utf-8")
        else:
            from scipy.io import savemat

            data = {"result": _mat(result.to_dict())}
            columns, rows = result.to_table()
            data["table"] = {
                _field(c): np.array([_mat(r[k]) for r in rows]) for k, c in enumerate(columns)
            }
            with open(tmp, "wb") as fh:
                savemat(fh, data, long_field_names=True, do_compression=True)
        os.replace(tmp, path)
    finally:
        tmp.unlink(missing_ok=True)
    return path


def _csv(columns, rows) -> str:
    out = io.StringIO()
    writer = csv.writer(out, lineterminator="\n")
    writer.writerow(columns)
    for row in rows:
        writer.writerow(["" if _missing(v) else v for v in row])
    return out.getvalue()


def _missing(v) -> bool:
    return v is None or (isinstance(v, float) and not math.isfinite(v))


def _field(name: str) -> str:
    """A MATLAB field name: letters, digits and underscores, starting with a letter."""
    s = "".join(ch if ch.isalnum() else "_" for ch in str(name))
    return s if s[:1].isalpha() else f"x_{s}"


def _mat(obj):
    """Nested data as savemat takes it: dicts as structs (field names cleaned), lists of
    numbers as arrays, None as NaN."""
    obj = clean(obj)
    if isinstance(obj, dict):
        return {_field(k): _mat(v) for k, v in obj.items()}
    if isinstance(obj, list):
        if obj and all(isinstance(v, int | float) or v is None for v in obj):
            return np.array([np.nan if v is None else v for v in obj], dtype=float)
        return np.array([_mat(v) for v in obj] + [None], dtype=object)[:-1]
    if obj is None:
        return np.nan
    return obj
