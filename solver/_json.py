"""JSON that other tools can read: non-finite numbers become null, never NaN.

Every JSON the toolkit writes or prints goes through :func:`dumps` (strict JSON,
``allow_nan=False``: RFC 8259 has no NaN or Infinity).  Where a null is not an ordinary
"not computed" of the record, :func:`with_status` says which numbers were not finite and
why, so that a reader can tell a missing value from a broken one.
"""

from __future__ import annotations

import json
import math

import numpy as np


def _floats(a: np.ndarray):
    """A float array as nested lists with non-finite entries as None (vectorised)."""
    if np.all(np.isfinite(a)):
        return a.tolist()
    return np.where(np.isfinite(a), a, None).tolist()


def clean(obj):
    """A copy of ``obj`` with NumPy scalars and arrays as plain Python, NaN/inf as None."""
    if isinstance(obj, dict):
        return {str(k): clean(v) for k, v in obj.items()}
    if isinstance(obj, list | tuple):
        if obj and all(type(v) is float for v in obj):  # the common case: a row of floats
            return _floats(np.asarray(obj, dtype=float))
        return [clean(v) for v in obj]
    if isinstance(obj, np.ndarray):
        if obj.dtype.kind in "fiub":
            return _floats(obj.astype(float)) if obj.dtype.kind == "f" else obj.tolist()
        return clean(obj.tolist())
    if isinstance(obj, np.generic):
        obj = obj.item()
    if isinstance(obj, float) and not math.isfinite(obj):
        return None
    return obj


def dumps(obj, **kwargs) -> str:
    return json.dumps(clean(obj), allow_nan=False, **kwargs)


def non_finite(obj, where: str = "") -> list[str]:
    """Where ``obj`` holds NaN or an infinity, in order, as ``modes[1].frequency_hz``."""
    if isinstance(obj, dict):
        return [
            p for k, v in obj.items() for p in non_finite(v, f"{where}.{k}" if where else str(k))
        ]
    if isinstance(obj, list | tuple):
        return [p for i, v in enumerate(obj) for p in non_finite(v, f"{where}[{i}]")]
    if isinstance(obj, np.ndarray):
        if obj.dtype.kind == "O":
            return non_finite(obj.tolist(), where)
        if obj.dtype.kind not in "fc":
            return []
        return [where + "".join(f"[{i}]" for i in idx) for idx in np.argwhere(~np.isfinite(obj))]
    if isinstance(obj, float | np.floating) and not math.isfinite(obj):
        return [where]
    return []


def with_status(obj: dict, why: str, *, shown: int = 5) -> dict:
    """``obj``, plus a ``"status"`` when it holds non-finite numbers (written as null by
    :func:`dumps`): how many, the first ``shown`` of them, and ``why``."""
    bad = non_finite(obj)
    if not bad:
        return obj
    more = f" and {len(bad) - shown} more" if len(bad) > shown else ""
    key = "json_status" if "status" in obj else "status"
    text = f"{len(bad)} non-finite number(s) written as null ({', '.join(bad[:shown])}{more})"
    return {**obj, key: f"{text}: {why}"}
